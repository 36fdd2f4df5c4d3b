"""Lagged friction at the defaults (issue "Physics at the defaults"): BDF2 measures sliding
from its history point q̂ (from x_t a stopping box reversed at −0.074 m/s), and friction's
normal force and tangent basis are lagged again at the converged state (IPC's friction
iterations), so a slide that starts compressed inside the barrier brakes by Coulomb's μ g h
per step (it lost 0.81 m/s in one step on a fixed table). Reference: Coulomb's law for a box
on a level surface, v_{n+1} = v_n − μ g h while sliding."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim

G = 9.81


def box(gap: float, v0: float, density: float = 1000.0) -> abdsim.SimplicialComplex:
    """A 10 cm cube, bottom `gap` above z = 0, sliding along x at v0."""
    sc = abdsim.geometry.box((0.1, 0.1, 0.1))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8, mass_density=density)
    T = np.eye(4)
    T[2, 3] = 0.05 + gap
    sc.transforms = T[None]
    V = np.zeros((1, 4, 4))
    V[0, 0, 3] = v0
    sc.instances["velocity"] = V
    return sc


def table() -> abdsim.SimplicialComplex:
    """A fixed 2 x 2 x 0.1 m slab with its top at z = 0."""
    sc = abdsim.geometry.box((2.0, 2.0, 0.1))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8)
    T = np.eye(4)
    T[2, 3] = -0.05
    sc.transforms = T[None]
    sc.instances["is_fixed"] = np.array([1])
    return sc


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_sliding_box_stops_without_reversing(integrator):
    """A box resting on the ground is set sliding at 0.3 m/s (μ = 0.5, dt = 0.01): it
    decelerates at μ g and stops; it never moves backwards faster than 5 mm/s."""
    scene = abdsim.Scene(dt=0.01, integrator=integrator, friction=0.5)
    scene.add_ground()
    h = scene.add(box(1.5e-3, 0.0))
    world = abdsim.World(scene)
    world.step(50)  # settle on the ground
    V = world.velocities()
    V[h.start, 0, 3] = 0.3
    world.set_state(velocities=V)
    v = []
    for _ in range(60):
        world.step()
        v.append(world.velocities()[h.start, 0, 3])
    v = np.array(v)
    decel = -np.diff(v[:4]) / 0.01
    np.testing.assert_allclose(decel, 0.5 * G, rtol=0.02)
    assert v.min() > -5e-3
    assert abs(v[-1]) < 1e-3


@pytest.mark.parametrize("obstacle", ["ground", "table"])
@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_slide_starting_inside_the_barrier_brakes_by_coulomb(integrator, obstacle):
    """A 1 kg box starting compressed 0.2 mm above the surface (inside d̂) at 1 m/s with
    μ = 0.1: its first step loses μ g h = 0.0098 m/s, within half of that."""
    mu, h_step = 0.1, 0.01
    scene = abdsim.Scene(dt=h_step, integrator=integrator, friction=mu)
    if obstacle == "ground":
        scene.add_ground()
    else:
        scene.add(table())
    hb = scene.add(box(2e-4, 1.0))
    world = abdsim.World(scene)
    world.step()
    loss = 1.0 - world.velocities()[hb.start, 0, 3]
    assert loss == pytest.approx(mu * G * h_step, abs=0.5 * mu * G * h_step)


def test_friction_iterations_setting():
    """0 friction iterations lags once at the step start; negative is refused."""
    scene = abdsim.Scene(friction_iterations=0)
    assert scene.settings.friction_iterations == 0
    with pytest.raises(ValueError, match="friction_iterations"):
        abdsim.Scene(friction_iterations=-1)
