"""Free fall against the parabola p_n = p0 + n h v0 + ½ g (n h)², v_n = v0 + n h g.

BDF1 moves a body nothing pushes onto it (implicit Euler's own recurrence, p0 + n h v0 +
h² g n(n+1)/2, is ½ h² g low per step; solver/world_ballistic.cpp, tests/solver/
test_ballistic.py); BDF2 integrates a constant acceleration exactly from that exact first
step. Free fall keeps A exactly (the shape energy is stationary at a rotation), so p follows
the parabola to round-off, whatever the rotation and wherever the centre of mass sits in the
body frame.
"""

from __future__ import annotations

import numpy as np
import pytest

G = np.array([0.0, 0.0, -9.81])
H = 0.01


def closed_form(integrator: str, p0: np.ndarray, v0: np.ndarray, n: int):
    """The parabola after n steps, for either integrator."""
    return p0 + n * H * v0 + 0.5 * H * H * G * n * n, v0 + n * H * G


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_one_body_every_step(tools, rng, integrator):
    sc = tools.make_box(offset=(0.05, -0.02, 0.03))  # centre of mass off the body origin
    A0 = tools.random_rotations(rng, 1)[0]
    p0, v0 = np.array([0.3, -1.0, 2.0]), np.array([0.5, 0.1, 3.0])
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = A0, p0
    sc.transforms = T[None]
    sc.instances["velocity"] = tools.rigid_velocity(A0, np.zeros(3), v0)[None]
    world = tools.world_of(sc, dt=H, integrator=integrator)
    for n in range(1, 41):
        world.step()
        p_ref, v_ref = closed_form(integrator, p0, v0, n)
        np.testing.assert_allclose(world.transforms()[0, :3, 3], p_ref, rtol=0, atol=1e-10)
        np.testing.assert_allclose(world.velocities()[0, :3, 3], v_ref, rtol=0, atol=1e-10)
    np.testing.assert_allclose(world.transforms()[0, :3, :3], A0, rtol=0, atol=1e-10)
    assert world.time == pytest.approx(40 * H, abs=1e-15)


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_thousand_bodies(tools, rng, integrator):
    n_each, steps = 500, 25
    geometries = [
        tools.make_box(n_each, constitution="OrthoPotential"),
        tools.make_box(n_each, constitution="ARAP", offset=(0.1, 0.0, 0.0)),
    ]
    p0 = rng.uniform(-10, 10, size=(2 * n_each, 3))
    v0 = rng.normal(size=(2 * n_each, 3))
    A0 = tools.random_rotations(rng, 2 * n_each)
    for k, sc in enumerate(geometries):
        sl = slice(k * n_each, (k + 1) * n_each)
        T = np.tile(np.eye(4), (n_each, 1, 1))
        T[:, :3, :3], T[:, :3, 3] = A0[sl], p0[sl]
        sc.transforms = T
        V = np.zeros((n_each, 4, 4))
        V[:, :3, 3] = v0[sl]
        sc.instances["velocity"] = V
    world = tools.world_of(*geometries, dt=H, integrator=integrator)
    assert world.num_bodies == 1000
    world.step(steps)
    p_ref, v_ref = closed_form(integrator, p0, v0, steps)
    np.testing.assert_allclose(world.transforms()[:, :3, 3], p_ref, rtol=0, atol=1e-10)
    np.testing.assert_allclose(world.velocities()[:, :3, 3], v_ref, rtol=0, atol=1e-10)
    np.testing.assert_allclose(world.transforms()[:, :3, :3], A0, rtol=0, atol=1e-10)
    assert world.diagnostics.linear_solver == "block_diagonal"


def test_bdf2_differs_from_bdf1(tools):
    """The two integrators really are different schemes: both put a falling body on the
    parabola, but a spinning one turns differently (implicit Euler damps the spin by
    O(h² ω²) per step, BDF2 by O(h³))."""
    A, p = {}, {}
    for integrator in ("bdf1", "bdf2"):
        sc = tools.make_box()
        sc.instances["velocity"] = tools.rigid_velocity(
            np.eye(3), np.array([0.0, 0.0, 20.0]), np.zeros(3)
        )[None]
        world = tools.world_of(sc, dt=H, integrator=integrator)
        world.step(10)
        A[integrator], p[integrator] = world.transforms()[0, :3, :3], world.transforms()[0, 2, 3]
    assert p["bdf1"] == pytest.approx(0.5 * G[2] * (10 * H) ** 2, abs=1e-12)
    assert p["bdf2"] == pytest.approx(0.5 * G[2] * (10 * H) ** 2, abs=1e-12)
    assert np.abs(A["bdf1"] - A["bdf2"]).max() > 1e-3
