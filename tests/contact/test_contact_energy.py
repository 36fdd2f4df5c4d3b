"""Contact adds no energy at the settings users run (issue "Physics at the defaults").

A body released at rest inside the barrier's reach d̂, or dropped onto the ground, must never
end up with more mechanical energy than it started with: the barrier stiffness κ only changes
while no pair is compressed (a stiffer κ would add energy to a compressed pair), a state that
starts inside d̂ gets the κ that makes it an equilibrium, and BDF2 restarts with a BDF1 step
where contact begins or ends (its extrapolation through the kink returned bounces above the
drop height). References: the mechanical energy ½ m v² + m g z computed here from the state
(not from the solver's diagnostics), and the start height."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from abdsim.sim.world import transforms_to_q

G = 9.81
D_HAT = 1e-3


def box_world(size: float, gap: float, integrator: str, dt: float, **settings):
    """A box of 500 kg/m³ (0.2 x 0.16 x 0.1 m at size 1) with its bottom `gap` above the
    ground, at rest."""
    extents = size * np.array([0.2, 0.16, 0.1])
    sc = abdsim.geometry.box(tuple(extents))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8, mass_density=500.0)
    T = np.eye(4)
    T[2, 3] = extents[2] / 2 + gap
    sc.transforms = T[None]
    scene = abdsim.Scene(dt=dt, integrator=integrator, **settings)
    scene.add(sc)
    scene.add_ground()
    return abdsim.World(scene), float(sc.meta["abd_mass"]), extents[2] / 2


def heights_and_energy(world, mass: float, half_height: float, steps: int):
    """Bottom height above the ground and ½ m v² + m g z per step (centre-of-mass terms: the
    box stays level)."""
    z, e = [], []
    for _ in range(steps):
        world.step()
        h = world.transforms()[0, 2, 3] - half_height
        v = world.velocities()[0, :3, 3]
        z.append(h)
        e.append(0.5 * mass * v @ v + mass * G * h)
    return np.array(z), np.array(e)


CASES = [(i, dt) for i in ("bdf1", "bdf2") for dt in (1e-3, 1e-2)]


@pytest.mark.parametrize("size", [1.0, 0.1])
@pytest.mark.parametrize("gap", [2e-4, 5e-4])
@pytest.mark.parametrize("integrator,dt", CASES)
def test_release_at_rest_inside_d_hat_does_not_leap(integrator, dt, gap, size):
    """Released at rest at a gap inside d̂: it stays (the start is made an equilibrium);
    it leapt 18.8 mm (BDF1) / 42.6 mm (BDF2) at dt = 1e-3 before."""
    world, m, half = box_world(size, gap, integrator, dt)
    z, _ = heights_and_energy(world, m, half, int(round(0.3 / dt)))
    assert z.max() - gap < 0.1 * D_HAT
    assert z.min() > 0.0
    assert abs(world.velocities()[0, 2, 3]) < 1e-3


@pytest.mark.parametrize("drop", [0.01, 0.05])
@pytest.mark.parametrize("integrator,dt", CASES)
def test_drop_never_rebounds_above_its_start(integrator, dt, drop):
    """Dropped from 1 and 5 cm: every later height and the mechanical energy stay below the
    start (before: 12.1 mm from 10 mm, 71.9 mm from 50 mm with BDF2)."""
    world, m, half = box_world(1.0, drop, integrator, dt)
    e0 = m * G * drop
    z, e = heights_and_energy(world, m, half, int(round(1.0 / dt)))
    assert z.max() <= drop + 1e-12
    assert e.max() <= e0 * (1 + 1e-9)
    assert z.min() > 0.0
    hit = np.argmax(z < D_HAT)
    assert z[hit:].max() < drop  # it did land, and came back lower


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_bouncing_energy_does_not_increase(integrator):
    """Total energy E = ½ q̇ᵀ M q̇ + m g z + κ B + κ v̄ Ψ (barrier and shape energy from the
    diagnostics' term values) of a bouncing box at dt = 1e-3: BDF1 never gains between
    steps; BDF2 (not monotone step to step: its velocity is a two-step difference) never
    exceeds the start and its flight energy falls from bounce to bounce."""
    world, m, half = box_world(1.0, 0.05, integrator, 1e-3)
    M = abdsim.mass_matrix(world.scene.handles[0].sc)
    e, flying = [], []
    for _ in range(1500):
        world.step()
        d = world.diagnostics
        qdot = transforms_to_q(world.velocities())[0]
        h = world.transforms()[0, 2, 3] - half
        stored = d.energies.get("ipc_contact", 0.0) + d.energies["shape"]
        e.append(0.5 * qdot @ M @ qdot + m * G * h + stored)
        flying.append(not d.min_contact_distance < D_HAT)
    e, flying = np.array(e), np.array(flying)
    e0 = m * G * 0.05
    assert e.max() <= e0 * (1 + 1e-9)
    if integrator == "bdf1":
        # Implicit Euler's step-to-step decrease is exact for convex potentials; the
        # barrier in body coordinates is only nearly so, and Newton stops at a tolerance:
        # resting steps move E by ~1e-8 E0 either way (a gain from κ would be ~E0).
        assert np.all(np.diff(e) <= 1e-6 * e0)
    # flight phases: energy at the top of each is below the previous one
    tops, run = [], []
    for ei, f in zip(e, flying, strict=True):
        if f:
            run.append(ei)
        elif run:
            tops.append(max(run))
            run = []
    assert len(tops) >= 2  # it landed (BDF1 barely bounces, BDF2 does)
    assert np.all(np.diff(tops) <= 1e-9 * e0)


def test_bdf2_restarts_with_bdf1_where_contact_begins_or_ends():
    """The steps' integrator order: BDF1 first, BDF2 in flight and at rest, BDF1 right after
    a step in which contact began or ended."""
    world, _, _ = box_world(1.0, 0.01, "bdf2", 1e-3)
    orders, touching = [], []
    for _ in range(400):
        d = world.step()
        orders.append(d.integrator_order)
        touching.append(d.min_contact_distance < D_HAT)
    orders, touching = np.array(orders), np.array(touching)
    assert orders[0] == 1 and orders[1] == 2
    changed = np.flatnonzero(touching[1:] != touching[:-1]) + 1  # steps where it switched
    assert len(changed) >= 2
    assert np.all(orders[changed[changed + 1 < len(orders)] + 1] == 1)
    assert (orders == 2).mean() > 0.9


def test_a_d_hat_too_large_for_a_part_is_an_error():
    """Scale: a 2 cm box behaves like a 20 cm one at d̂ = 1 mm (the tests above), and a d̂
    that reaches across a quarter of a part is refused, naming the body and a d̂ to use."""
    box_world(0.1, 2e-4, "bdf1", 1e-2)  # 2 x 1.6 x 1 cm with d̂ = 1 mm: fine
    with pytest.raises(ValueError, match=r"d_hat = 0.01 m is not small against body 0"):
        box_world(0.1, 2e-3, "bdf1", 1e-2, d_hat=1e-2)
