"""Per-body flags: is_fixed, is_dynamic = 0 (quasi-static), external_kinetic, and
kinematic (scripted) bodies."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim

H = 0.01
G = np.array([0.0, 0.0, -9.81])


def test_fixed_bodies_never_move(tools):
    sc = tools.make_box(3)
    T = np.tile(np.eye(4), (3, 1, 1))
    T[:, :3, 3] = [[0, 0, 1], [2, 0, 1], [4, 0, 1]]
    T[2, :3, :3] = [[1.0, 0.2, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.1]]  # even when deformed
    sc.transforms = T
    sc.instances["velocity"] = np.stack(
        [tools.rigid_velocity(np.eye(3), [1.0, 2.0, 3.0], [1.0, 0.0, 0.0])] * 3
    )
    sc.instances["is_fixed"] = np.array([1, 0, 1])
    world = tools.world_of(sc, dt=H)
    world.step(30)
    out = world.transforms()
    assert np.array_equal(out[[0, 2]], T[[0, 2]])  # bit-identical
    assert np.array_equal(world.velocities()[[0, 2]], np.zeros((2, 4, 4)))
    assert out[1, 2, 3] < 1.0 - 0.4  # the free one fell


def test_quasi_static_body_ignores_velocity_and_settles(tools):
    sc = tools.make_box()
    T = np.eye(4)
    T[:3, :3] = [[1.0, 0.3, 0.0], [0.0, 1.0, 0.0], [0.0, 0.1, 0.9]]
    sc.transforms = T[None]
    sc.instances["velocity"] = tools.rigid_velocity(np.eye(3), [0, 0, 3.0], [1.0, 0.0, 0.0])[None]
    sc.instances["is_dynamic"] = np.array([0])
    world = tools.world_of(sc, dt=H, gravity=(0, 0, 0))
    world.step(3)
    A = world.transforms()[0, :3, :3]
    assert np.abs(A @ A.T - np.eye(3)).max() < 1e-6
    settled = world.transforms()
    world.step(20)
    np.testing.assert_allclose(world.transforms(), settled, atol=1e-12)  # no drift
    np.testing.assert_allclose(world.velocities(), 0, atol=1e-9)


def test_quasi_static_under_gravity_moves_h2g_per_step(tools):
    """q̃ = q_t + h² g: without inertia a quasi-static body sinks h² g per step."""
    sc = tools.make_box()
    sc.instances["is_dynamic"] = np.array([0])
    world = tools.world_of(sc, dt=H)
    world.step(10)
    np.testing.assert_allclose(world.transforms()[0, :3, 3], 10 * H * H * G, atol=1e-14)
    np.testing.assert_allclose(world.velocities()[0, :3, 3], H * G, atol=1e-12)


def test_external_kinetic_without_an_energy_raises(tools):
    sc = tools.make_box(2)
    sc.instances["external_kinetic"] = np.array([0, 1])
    world = tools.world_of(sc, dt=H)
    with pytest.raises(abdsim.SolverError, match="body 1.*external_kinetic"):
        world.step()
    assert world.step_count == 0


def _helix(t: float) -> np.ndarray:
    T = np.eye(4)
    c, s = np.cos(2.0 * t), np.sin(2.0 * t)
    T[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    T[:3, 3] = [np.cos(t), np.sin(t), 0.3 * t]
    return T


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_kinematic_body_follows_its_schedule_exactly(tools, integrator):
    sc = tools.make_box(2)
    world = tools.world_of(sc, dt=H, integrator=integrator)
    world.set_state(transforms=np.stack([_helix(0.0), np.eye(4)]))
    world.set_kinematic_schedule(0, _helix)
    assert world.is_kinematic(0) is False  # the schedule applies from the next step
    previous = [_helix(0.0)]
    for n in range(1, 21):
        world.step()
        target = _helix(n * H)
        assert np.array_equal(world.transforms()[0], target)  # exactly, bit for bit
        previous.append(target)
    assert world.is_kinematic(0)
    # Velocity from the prescribed motion: the backward difference of the integrator.
    if integrator == "bdf1":
        v_ref = (previous[-1] - previous[-2]) / H
    else:
        v_ref = (3 * previous[-1] - 4 * previous[-2] + previous[-3]) / (2 * H)
    v_ref[3] = 0.0
    np.testing.assert_allclose(world.velocities()[0], v_ref, atol=1e-12)
    # The other body fell freely meanwhile.
    assert world.transforms()[1, 2, 3] < -0.01


def test_kinematic_target_then_rest_then_release(tools):
    sc = tools.make_box()
    world = tools.world_of(sc, dt=H, gravity=(0, 0, 0))
    T = np.eye(4)
    T[:3, 3] = [0.01, 0.0, 0.0]
    world.set_kinematic_target(0, T)
    world.step()
    assert np.array_equal(world.transforms()[0], T)
    np.testing.assert_allclose(world.velocities()[0, :3, 3], [1.0, 0.0, 0.0], atol=1e-12)
    world.step(3)  # no new target: it rests at the last one
    assert np.array_equal(world.transforms()[0], T)
    np.testing.assert_allclose(world.velocities()[0], 0.0, atol=0)
    world.set_kinematic_target(0, _helix(0.0) @ np.diag([1, 1, 1, 1.0]) + T - np.eye(4))
    world.step()
    world.release_kinematic(0)
    assert not world.is_kinematic(0)
    v = world.velocities()[0, :3, 3].copy()
    p = world.transforms()[0, :3, 3].copy()
    world.step(10)  # ballistic with the velocity it had (no gravity)
    np.testing.assert_allclose(world.transforms()[0, :3, 3], p + 10 * H * v, atol=1e-10)
