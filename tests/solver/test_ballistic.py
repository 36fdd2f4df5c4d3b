"""BDF1 moves the bodies nothing pushes along their exact parabola (solver/world_ballistic.cpp).

Implicit Euler's free flight is ½ h² g low per step; for a body that no term, constraint or
contact pushes at the solution, the step's minimiser moves by exactly −½ h² g when q̃ takes
½ h² g, so such bodies are shifted onto the closed form p0 + t v0 + ½ g t² (the velocity,
v0 + t g, is the same either way). Everything that a term pushes keeps implicit Euler's
recurrence p_n = p0 + n h v0 + ½ n (n + 1) g h², checked here against its closed form: a
hovering body held by an applied wrench, bodies under a Python term (all of them when the term
names none), and a body whose exact endpoint would cross a fixed slab (the shift is undone).
"""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from abdsim import _core

G = np.array([0.0, 0.0, -9.81])
H = 0.01


def parabola(p0, v0, t):
    return p0 + t * v0 + 0.5 * G * t * t


def implicit_euler(p0, v0, n, h=H):
    return p0 + n * h * v0 + 0.5 * n * (n + 1) * h * h * G


class Zero(_core.PythonEnergyTerm):
    """A term with no energy anywhere: it pushes nothing, but says nothing about it either."""

    def __init__(self, bodies=None):
        if bodies is None:
            super().__init__()
        else:
            super().__init__(bodies=bodies)

    def name(self):
        return "zero"

    def value(self, q):
        return 0.0

    def gradient(self, q):
        return np.zeros_like(q)

    def hessian(self, q):
        return []


def test_wrench_held_body_stays_put(tools):
    """A wrench of m g upwards holds a body still: shifted like a free body it would rise by
    ½ g h² (0.49 mm) per step."""
    sc = tools.make_box()
    world = tools.world_of(sc, dt=H, integrator="bdf1")
    m = float(sc.meta["abd_mass"])
    world.apply_wrench(0, force=-m * G)
    p0 = world.transforms()[0, :3, 3].copy()
    world.step(50)
    np.testing.assert_allclose(world.transforms()[0, :3, 3], p0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(world.velocities()[0, :3, 3], 0.0, rtol=0, atol=1e-12)


@pytest.mark.parametrize("named", [False, True])
def test_python_terms_keep_implicit_euler_where_they_may_push(tools, named):
    """A Python term that names its bodies keeps implicit Euler on those only; one that names
    none may push any body, so every body keeps it."""
    sc = tools.make_box(2)
    T = np.tile(np.eye(4), (2, 1, 1))
    T[1, 0, 3] = 1.0
    sc.transforms = T
    world = tools.world_of(sc, dt=H, integrator="bdf1")
    world.add_term(Zero(bodies=[0]) if named else Zero())
    p0 = world.transforms()[:, :3, 3].copy()
    v0 = np.zeros(3)
    for n in range(1, 21):
        world.step()
        p = world.transforms()[:, :3, 3]
        np.testing.assert_allclose(p[0], implicit_euler(p0[0], v0, n), rtol=0, atol=1e-12)
        expected = parabola(p0[1], v0, n * H) if named else implicit_euler(p0[1], v0, n)
        np.testing.assert_allclose(p[1], expected, rtol=0, atol=1e-12)


def test_shift_that_would_cross_is_undone():
    """A box thrown up under a fixed slab at h = 0.02: implicit Euler's end stops 1.5 mm short
    of the slab (beyond d̂ = 1 mm: nothing pushes it), the parabola's 1.96 mm higher would be
    0.46 mm inside it. The step keeps implicit Euler's end, the box stays below the slab, and
    the next steps (now within d̂ of it) are solved with contact, never crossing."""
    h, half = 0.02, 0.05
    scene = abdsim.Scene(dt=h, integrator="bdf1")
    ball = abdsim.geometry.box((0.1, 0.1, 0.1))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(ball, kappa=1e8)
    v0 = np.array([0.0, 0.0, 1.0])
    ball.instances["velocity"] = np.array(
        [[[0, 0, 0, v0[0]], [0, 0, 0, v0[1]], [0, 0, 0, v0[2]], [0, 0, 0, 0]]], dtype=float
    )
    T = np.eye(4)
    T[2, 3] = 1.0
    ball.transforms = T[None]
    scene.add(ball)
    top_ie = implicit_euler(np.array([0, 0, 1.0]), v0, 1, h)[2] + half
    slab = abdsim.geometry.box((1.0, 1.0, 0.1))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(slab, kappa=1e8)
    S = np.eye(4)
    S[2, 3] = top_ie + 1.5e-3 + 0.05
    slab.transforms = S[None]
    slab.instances["is_fixed"] = np.array([1])
    scene.add(slab)
    world = abdsim.World(scene)
    d = world.step()
    assert d.substeps <= 1
    assert world.transforms()[0, 2, 3] == pytest.approx(top_ie - half, abs=1e-12)
    assert world.velocities()[0, 2, 3] == pytest.approx(v0[2] + h * G[2], abs=1e-12)
    underside = S[2, 3] - 0.05
    for _ in range(10):
        world.step()
        top = world.vertices(world.scene.handles[0])[0][:, 2].max()
        assert top < underside
