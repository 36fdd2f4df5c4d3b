"""Exact joints in the Newton solve against independent references: Pinocchio's ABA
integrated with RK4 at a fine step (pendulums, a slider on a swinging link), the closed form
of a slide down an incline, and the joint rows at every step (violation)."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from tests.joints.conftest import (
    LINK,
    aba_rk4,
    chain_scene,
    link,
    pin_inertia,
    pinocchio_chain,
    rot_y,
)


def _run(world: abdsim.World, steps: int):
    """Joint positions after each step (first row: at load) and the worst violations."""
    qs, worst = [world.joint_positions()], np.zeros(2)
    for _ in range(steps):
        d = world.step()
        qs.append(world.joint_positions())
        worst = np.maximum(worst, (d.joint_violation, d.joint_violation_angle))
    return np.array(qs), worst


@pytest.mark.parametrize("q0", [(0.5,), (0.5, -0.3)], ids=["simple", "double"])
def test_pendulum_matches_pinocchio_aba(q0):
    q0 = np.array(q0)
    scene, handles = chain_scene(q0, kappa=1e10)  # BDF2, dt = 1e-3, no damping
    world = abdsim.World(scene)
    qs, worst = _run(world, 1000)
    ref = aba_rk4(pinocchio_chain(handles), q0, np.zeros(len(q0)), 1.0, 1e-4, 10)
    error = np.abs(qs + q0 - ref).max()
    assert error < 1e-3, error  # measured: 5e-5 (simple), 1.8e-4 rad (double)
    assert worst[0] <= 1e-6 and worst[1] <= 1e-6, worst
    # it really swings: the reference leaves the start by more than the tolerance a lot
    assert np.abs(ref - q0).max() > 0.5


def test_double_pendulum_bdf2_energy_drift():
    """Mechanical energy (Pinocchio's, from abdsim's joint states) over 1 s of BDF2."""
    import pinocchio as pin

    q0 = np.array([0.5, -0.3])
    scene, handles = chain_scene(q0)
    world = abdsim.World(scene)
    model = pinocchio_chain(handles)
    data = model.createData()

    def energy():
        q, v = world.joint_positions() + q0, world.joint_velocities()
        return pin.computeKineticEnergy(model, data, q, v) + pin.computePotentialEnergy(
            model, data, q
        )

    e0 = energy()
    energies = []
    for _ in range(10):
        world.step(100)
        energies.append(energy())
    swing = e0 - pin.computePotentialEnergy(model, data, np.zeros(2))  # released at the bottom
    drift = max(abs(e - e0) for e in energies) / swing
    assert drift < 1e-3, drift  # measured 1.9e-4 of the energy the swing releases


def test_double_pendulum_bdf1_is_dissipative_but_held():
    """BDF1 damps the swing (its known numerical dissipation) but the joints still hold."""
    q0 = np.array([0.5, -0.3])
    scene, handles = chain_scene(q0, integrator="bdf1")
    qs, worst = _run(abdsim.World(scene), 1000)
    ref = aba_rk4(pinocchio_chain(handles), q0, np.zeros(2), 1.0, 1e-4, 10)
    error = np.abs(qs + q0 - ref).max()
    assert 1e-3 < error < 0.05, error  # measured 1.5e-2 rad: BDF2 is the accurate choice
    assert worst.max() <= 1e-6


@pytest.mark.parametrize("kappa", [1e8, 1e11])
@pytest.mark.parametrize("dt", [1e-3, 1e-2])
@pytest.mark.parametrize("densities", [(1e3, 1e7, 1e3), (1e7, 1e3, 1e3), (1e3, 1e-1, 1e3)])
def test_mass_ratio_chain_holds(kappa, dt, densities):
    """Three links with a 1e4 mass ratio between neighbours, any dt, κ over the spec's range."""
    scene, _ = chain_scene([0.5, -0.3, 0.8], kappa=kappa, densities=list(densities), dt=dt)
    world = abdsim.World(scene)
    qs, worst = _run(world, int(round(0.3 / dt)))
    assert worst[0] <= 1e-6 and worst[1] <= 1e-6, worst
    assert np.abs(qs[-1] - qs[0]).max() > 0.05  # the chain moved


def test_prismatic_on_incline_follows_closed_form():
    """A body on a world slide inclined θ from the vertical: s(t) = ½ g cos θ t²."""
    theta = 0.6
    axis = np.array([np.sin(theta), 0.0, -np.cos(theta)])
    scene = abdsim.Scene(dt=1e-3, integrator="bdf2", contact=False)
    sc = link(extents=(0.1, 0.1, 0.1))
    h = scene.add(sc)
    scene.add_joint("prismatic", None, h, anchor=(0, 0, 0), axis=axis, name="slide")
    world = abdsim.World(scene)
    qs, worst = _run(world, 500)
    t = np.arange(501) * 1e-3
    error = np.abs(qs[:, 0] - 0.5 * 9.81 * np.cos(theta) * t**2).max()
    assert error < 1e-4, error
    assert worst.max() <= 1e-6
    # the velocity too (MuJoCo's slide qvel)
    assert world.joint_velocities()[0] == pytest.approx(9.81 * np.cos(theta) * 0.5, rel=1e-3)


def test_slider_on_swinging_link_matches_pinocchio():
    """A prismatic joint whose parent moves (its offset rows are bilinear, linearised per
    Newton iteration and projected back): a block sliding along a swinging link, against
    Pinocchio (RY + PZ) with ABA and RK4."""
    import pinocchio as pin

    q1 = 0.5
    scene = abdsim.Scene(dt=1e-3, integrator="bdf2", contact=False)
    arm = link(kappa=1e10)
    T = np.eye(4)
    T[:3, :3] = rot_y(q1)
    arm.transforms = T[None]
    h_arm = scene.add(arm)
    block = abdsim.geometry.box(0.1)
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(block, kappa=1e10)
    anchor = rot_y(q1) @ np.array([0.0, 0.0, -0.5])
    T = np.eye(4)
    T[:3, :3] = rot_y(q1)
    T[:3, 3] = anchor
    block.transforms = T[None]
    h_block = scene.add(block)
    scene.add_joint("revolute", None, h_arm, anchor=(0, 0, 0), axis=(0, 1, 0))
    scene.add_joint("prismatic", h_arm, h_block, anchor=anchor, axis=rot_y(q1)[:, 2])
    world = abdsim.World(scene)
    qs, worst = _run(world, 600)

    model = pin.Model()
    j1 = model.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "hinge")
    model.appendBodyToJoint(j1, pin_inertia(arm), pin.SE3.Identity())
    j2 = model.addJoint(j1, pin.JointModelPZ(), pin.SE3(np.eye(3), np.array([0, 0, -0.5])), "slide")
    model.appendBodyToJoint(j2, pin_inertia(block), pin.SE3.Identity())
    ref = aba_rk4(model, [q1, 0.0], np.zeros(2), 0.6, 1e-4, 10)
    error = np.abs(qs + [q1, 0.0] - ref).max(axis=0)
    assert error.max() < 1e-3, error
    assert np.abs(ref[:, 1]).max() > 0.05  # it slid
    assert worst.max() <= 1e-6, worst


def test_pendulum_follows_a_kinematic_base():
    """A pendulum hinged to a kinematic body that is moved: the start of every step is
    projected back onto the joint (the base's target moved it away) and the joint holds."""
    scene = abdsim.Scene(dt=1e-3, integrator="bdf2", contact=False)
    base = abdsim.geometry.box(0.1)
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(base, kappa=1e10)
    h_base = scene.add(base, kinematic=True)
    h_link = scene.add(link())
    scene.add_joint("revolute", h_base, h_link, anchor=(0, 0, 0), axis=(0, 1, 0))
    world = abdsim.World(scene)
    worst = 0.0
    for k in range(1, 301):
        T = np.eye(4)
        T[0, 3] = 0.5 * (k * 1e-3) ** 2 * 4.0  # accelerate the base along x at 4 m/s²
        world.set_kinematic_target(h_base.start, T)
        d = world.step()
        worst = max(worst, d.joint_violation, d.joint_violation_angle)
    assert worst <= 1e-6, worst
    # the link lags behind an accelerating support: it swings back (positive about y)
    # towards tan θ = a/g
    assert 0.05 < world.joint_positions()[0] < 2 * np.arctan(4.0 / 9.81)


def test_set_state_off_the_joint_is_projected_back():
    scene, handles = chain_scene([0.3])
    world = abdsim.World(scene)
    T = world.transforms()
    T[0, :3, 3] += (0.01, 0.0, 0.0)  # the link's top moved 1 cm off the world anchor
    world.set_state(T)
    assert world.joint_violation()[0] == pytest.approx(0.01)
    d = world.step()
    assert d.joint_violation <= 1e-9
    assert abs(world.joint_positions()[0]) < 0.05  # the projection turned it a little (1.4e-2)


LINK_LENGTH = LINK[2]


def rot_x(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


@pytest.mark.parametrize(
    "tilts",
    [(0.3, 0.3 + np.pi, 0.3 + np.pi - 2.5), (0.0, 2.5, 2.5), (1e-9, 0.0, 0.0), (-0.4, 0.5, 0.2)],
)
def test_joint_violation_is_the_worst_over_the_joints(tilts):
    """Three hanging links tilted about x (across their y hinges) by `tilts`, each about its
    top: joint k's axes are |tilt_k − tilt_{k−1}| apart (the world's axis: tilt 0; up to π,
    antiparallel), and its anchors 2 |sin(tilt_{k−1} / 2)| (the parent's bottom swung about
    its top). The worst of each, as the closed forms say."""
    scene, _ = chain_scene([0.0, 0.0, 0.0])
    world = abdsim.World(scene)
    T = np.repeat(np.eye(4)[None], 3, axis=0)
    for k, tilt in enumerate(tilts):
        T[k, :3, :3] = rot_x(tilt)
        T[k, :3, 3] = (0.0, 0.0, -k * LINK_LENGTH)
    world.set_state(T)
    previous = np.concatenate([[0.0], tilts[:-1]])
    angles = np.abs(np.asarray(tilts) - previous)
    angles = np.minimum(angles, 2 * np.pi - angles)
    gaps = 2 * np.abs(np.sin(previous / 2)) * LINK_LENGTH
    position, angle = world.joint_violation()
    assert position == pytest.approx(gaps.max(), rel=1e-12, abs=1e-15)
    assert angle == pytest.approx(angles.max(), rel=1e-9)
