"""Joint physics and actuation as energy terms, against independent references: Pinocchio
(ABA + RK4 with the same joint torques; CRBA for the joint inertia), MuJoCo's position
actuator, and closed forms (constant torques, velocity servo, dry friction, free-body
wrenches); limits never crossed and no energy gained at the stops."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import abdsim
from tests.joints.conftest import aba_rk4, chain_scene, link, pinocchio_chain

_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))  # MJCF fullinertia order


def _with(scene: abdsim.Scene, **physics) -> None:
    """Give the scene's first joint some physics (the scene keeps frozen handles)."""
    scene._joints[0] = replace(scene._joints[0], **physics)


def _hanging(gravity=(0.0, 0.0, -9.81), omega=0.0, **physics):
    """One link hanging straight down from a world hinge about y (angle 0 at the bottom)."""
    scene = abdsim.Scene(dt=1e-3, integrator="bdf2", contact=False, gravity=gravity)
    sc = link(kappa=1e10)
    V = np.zeros((4, 4))
    V[:3, :3] = np.array([[0, 0, omega], [0, 0, 0], [-omega, 0, 0]])  # [ω]× A, ω = (0, ω, 0)
    sc.instances["velocity"] = V[None]
    h = scene.add(sc)
    j = scene.add_joint("revolute", None, h, anchor=(0, 0, 0), axis=(0, 1, 0), **physics)
    return scene, h, j


def _joint_inertia(h) -> float:
    import pinocchio as pin

    model = pinocchio_chain([h])
    return float(pin.crba(model, model.createData(), np.zeros(1))[0, 0])


def test_spring_and_damping_match_pinocchio():
    q0 = np.array([0.5])
    scene, handles = chain_scene(q0)
    _with(scene, stiffness=5.0, damping=0.5, ref=0.3)
    world = abdsim.World(scene)
    qs = [world.joint_positions()]
    for _ in range(1000):
        world.step()
        qs.append(world.joint_positions())
    ref = aba_rk4(
        pinocchio_chain(handles),
        q0,
        np.zeros(1),
        1.0,
        1e-4,
        10,
        tau=lambda q, v: -5.0 * (q - q0 - 0.3) - 0.5 * v,
    )
    error = np.abs(np.array(qs) + q0 - ref).max()
    assert error < 1e-4, error  # measured 6e-6 rad
    assert np.abs(ref - q0).max() > 0.4


def test_motor_with_gear_and_armature_follow_closed_form():
    """No gravity, a constant motor torque gear·u on inertia I + armature: θ = ½ τ/(I+a) t²."""
    scene, h, j = _hanging(gravity=(0, 0, 0), armature=0.5)
    scene.add_actuator(j, "motor", gear=2.0, ctrl_range=(-1.0, 1.0))
    world = abdsim.World(scene)
    world.ctrl[:] = 3.0  # clamped to 1: τ = 2 N·m
    world.step(500)
    inertia = _joint_inertia(h) + 0.5
    expected = 0.5 * 2.0 / inertia * 0.5**2
    assert world.joint_positions()[0] == pytest.approx(expected, rel=1e-4)
    assert world.joint_velocities()[0] == pytest.approx(2.0 / inertia * 0.5, rel=1e-4)


def test_generalized_force_and_dry_friction_loss():
    scene, h, j = _hanging(gravity=(0, 0, 0), frictionloss=1.0)
    world = abdsim.World(scene)
    world.set_joint_forces([0.5])  # below the friction loss: (nearly) stuck
    world.step(300)
    assert abs(world.joint_positions()[0]) < 1e-3 * 0.3  # creep below ε = 1e-3 rad/s
    world = abdsim.World(scene)
    world.set_joint_forces([2.0])  # above it: accelerates with (τ − F)/I
    world.step(500)
    expected = 0.5 * (2.0 - 1.0) / _joint_inertia(h) * 0.5**2
    assert world.joint_positions()[0] == pytest.approx(expected, rel=1e-3)


def test_velocity_actuator_reaches_its_speed():
    scene, h, j = _hanging(gravity=(0, 0, 0))
    scene.add_actuator(j, "velocity", kv=10.0)
    world = abdsim.World(scene)
    world.ctrl[0] = 2.0
    world.step(2000)
    assert world.joint_velocities()[0] == pytest.approx(2.0, abs=1e-3)


def test_limits_are_never_crossed_and_gain_no_energy():
    """Released at the bottom at 3 rad/s (enough to pass 1.2 rad): it hits +0.5 and −0.5."""
    scene, h, j = _hanging(omega=3.0, limits=(-0.5, 0.5))
    world = abdsim.World(scene)
    rb = abdsim.to_rigid_body(h.sc)
    inertia, lever = _joint_inertia(h), -float(rb.mass_center[2])

    def energy():
        theta, rate = world.joint_positions()[0], world.joint_velocities()[0]
        return 0.5 * inertia * rate**2 - rb.mass * 9.81 * lever * np.cos(theta)

    e0, worst_e, lo, hi = energy(), -np.inf, 0.0, 0.0
    for _ in range(2000):
        world.step()
        theta = world.joint_positions()[0]
        lo, hi = min(lo, theta), max(hi, theta)
        worst_e = max(worst_e, energy())
    assert -0.5 < lo and hi < 0.5  # never beyond (not even by 1e-6)
    assert lo < -0.5 + 2e-3 and hi > 0.5 - 2e-3  # it reached both stops
    assert worst_e <= e0 + 1e-6 * abs(e0), (worst_e, e0)


def test_position_actuator_settles_like_mujoco():
    import mujoco

    kp, kv, target = 50.0, 5.0, 0.6
    scene, h, j = _hanging()
    scene.add_actuator(j, "position", kp=kp, kv=kv)
    world = abdsim.World(scene)
    world.ctrl[:] = target
    rb = abdsim.to_rigid_body(h.sc)
    inertia = np.asarray(rb.inertia)
    xml = f"""<mujoco><option timestep="0.001" integrator="RK4"/>
      <worldbody><body name="link"><joint name="j" type="hinge" axis="0 1 0"/>
        <inertial pos="{" ".join(map(str, rb.mass_center))}" mass="{rb.mass}"
          fullinertia="{" ".join(str(inertia[i, j]) for i, j in _PAIRS)}"/>
      </body></worldbody>
      <actuator><position joint="j" kp="{kp}" kv="{kv}"/></actuator></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.ctrl[0] = target
    ours, theirs = [], []
    for _ in range(3000):
        world.step()
        mujoco.mj_step(model, data)
        ours.append(world.joint_positions()[0])
        theirs.append(data.qpos[0])
    ours, theirs = np.array(ours), np.array(theirs)
    assert abs(ours[-1] - theirs[-1]) < 1e-3, (ours[-1], theirs[-1])
    # the steady state balances the servo against gravity (not the target itself)
    lever = -float(rb.mass_center[2])
    assert kp * (target - ours[-1]) == pytest.approx(
        rb.mass * 9.81 * lever * np.sin(ours[-1]), rel=1e-3
    )
    assert np.abs(ours - theirs).max() < 5e-3  # the step response too


def test_apply_wrench_on_a_free_body():
    scene = abdsim.Scene(dt=1e-3, integrator="bdf2", contact=False, gravity=(0, 0, 0))
    sc = abdsim.geometry.box((0.4, 0.2, 0.1))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e10)
    h = scene.add(sc)
    world = abdsim.World(scene)
    rb = abdsim.to_rigid_body(sc)
    force, torque = np.array([1.0, 2.0, 0.0]), np.array([0.0, 0.0, 0.05])
    world.apply_wrench(h, force=force, torque=torque)
    world.step(500)
    q = world.q[0]
    np.testing.assert_allclose(q[:3], 0.5 * force / rb.mass * 0.25, rtol=1e-4)
    A = q[3:].reshape(3, 3)
    angle = np.arctan2(A[1, 0], A[0, 0])
    assert angle == pytest.approx(0.5 * torque[2] / rb.inertia[2, 2] * 0.25, rel=1e-3)
    # a force off the centre of mass also turns it
    world.clear_wrenches()
    world.apply_wrench(0, force=(0, 0, 1.0), point=world.q[0][:3] + A @ np.array([0.2, 0, 0]))
    world.step(10)
    assert abs(world.velocities()[0][2, 0]) > 0  # tips about y


def test_jointed_steps_are_deterministic_across_thread_counts():
    runs = []
    for threads in (1, 2):
        scene, handles = chain_scene([0.5, -0.3, 0.2], num_threads=threads)
        _with(scene, damping=0.2, limits=(-1.0, 1.0))
        scene.add_actuator(scene.joints[1], "position", kp=20.0, kv=2.0)
        world = abdsim.World(scene)
        world.ctrl[:] = 0.4
        world.step(200)
        runs.append(world.q)
    np.testing.assert_array_equal(runs[0], runs[1])


def test_energies_off_skips_only_the_report():
    # SceneSettings.energies = False (MuJoCo's mjENBL_ENERGY off): the step-end energies are
    # not evaluated and StepDiagnostics.energies is empty; the motion, the joint positions
    # (whose hinge angles the joint set then reads without the energies' evaluation at the
    # step end) and every other diagnostic are those of a run that reports them, to the bit.
    runs = {}
    for energies in (True, False):
        scene, _ = chain_scene([0.5, -0.3, 0.2])
        scene.settings.energies = energies
        _with(scene, damping=0.2, limits=(-1.0, 1.0))
        scene.add_actuator(scene.joints[1], "position", kp=20.0, kv=2.0)
        world = abdsim.World(scene)
        world.ctrl[:] = 0.4
        world.step(300)
        runs[energies] = (world.q, world.joint_positions(), world.history)
    (q_on, pos_on, hist_on), (q_off, pos_off, hist_off) = runs[True], runs[False]
    np.testing.assert_array_equal(q_on, q_off)
    np.testing.assert_array_equal(pos_on, pos_off)
    assert all(d.energies == {} for d in hist_off)
    assert all(set(d.energies) == {"kinetic", "shape", "joints", "total"} for d in hist_on)
    for on, off in zip(hist_on, hist_off, strict=True):
        assert replace(on, energies={}, wall_time=0.0, profile={}) == replace(
            off, wall_time=0.0, profile={}
        )
