"""Loaded robots move by their own dynamics (issue 11): dm_control's pendulum and acrobot
against MuJoCo RK4, example-robot-data's double pendulum against Pinocchio ABA + RK4, and a
thrust-driven drone against MuJoCo, all from ``load_mjcf`` / ``load_urdf`` defaults."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from abdsim.bridges import load_urdf

from .conftest import load_mjcf_quietly, suite_xml


@pytest.mark.parametrize(
    ("name", "q0", "v0"),
    [("pendulum.xml", [2.0], [1.0]), ("acrobot.xml", [0.6, -0.4], [0.0, 0.5])],
)
def test_dm_control_swings_like_mujoco_rk4(name, q0, v0):
    """From a non-trivial state, 1 s at dt = 1e-3 in both simulators (the file's own joint
    damping and masses): joint angles within 5e-3 rad of MuJoCo's RK4 all along."""
    import mujoco

    dt = 1e-3
    result = load_mjcf_quietly(suite_xml(name))
    world = result.make_world(integrator="bdf2", contact=False, dt=dt)
    result.set_world_state(world, q0, v0)
    model = result.model
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.timestep = dt
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = q0, v0
    assert np.allclose(result.qpos_from_world(world), q0, atol=1e-12)
    assert np.allclose(result.qvel_from_world(world), v0, atol=1e-9)
    worst = 0.0
    for _ in range(1000):
        world.step()
        mujoco.mj_step(model, data)
        worst = max(worst, np.abs(result.qpos_from_world(world) - data.qpos).max())
    assert np.abs(data.qpos - q0).max() > 1.0  # it swung
    assert worst < 5e-3, worst
    assert max(world.joint_violation()) <= 1e-6


def test_double_pendulum_urdf_matches_pinocchio_aba_rk4(robot_urdf):
    """example-robot-data's double pendulum, its URDF damping included, from (0.5, -0.3) rad
    at rest: 1 s at dt = 1e-3 against Pinocchio's ABA integrated by RK4."""
    import pinocchio as pin

    path = robot_urdf("double_pendulum_description", "double_pendulum.urdf")
    q0 = np.array([0.5, -0.3])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = load_urdf(path, q=q0)
    assert result.joint_names == ["joint1", "joint2"]
    world = result.make_world(integrator="bdf2", dt=1e-3, gravity=(0.0, 0.0, -9.81), contact=False)
    assert [j.damping for j in world.joints] == [0.05, 0.05]  # URDF <dynamics damping>
    model = result.model
    model.gravity.linear = np.array([0.0, 0.0, -9.81])
    data = model.createData()
    damping = np.array(model.damping)

    def accel(q, v):
        return pin.aba(model, data, q, v, -damping * v)

    q, v, h, worst = q0.copy(), np.zeros(2), 1e-3, 0.0
    for _ in range(1000):
        k1v, k1q = accel(q, v), v
        k2v, k2q = accel(q + h / 2 * k1q, v + h / 2 * k1v), v + h / 2 * k1v
        k3v, k3q = accel(q + h / 2 * k2q, v + h / 2 * k2v), v + h / 2 * k2v
        k4v, k4q = accel(q + h * k3q, v + h * k3v), v + h * k3v
        q = q + h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q)
        v = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        world.step()
        worst = max(worst, np.abs(result.qpos_from_world(world) - q).max())
    assert np.abs(q - q0).max() > 0.3  # it swung
    assert worst < 1e-3, worst
    assert np.abs(result.qvel_from_world(world) - v).max() < 1e-2


_DRONE = """<mujoco><option timestep="0.002" gravity="0 0 -9.81"/>
  <worldbody><body name="drone" pos="0 0 1"><freejoint name="root"/>
    <geom type="box" size="0.1 0.1 0.02" mass="0.8"/>
    <site name="r0" pos="0.15 0.15 0"/><site name="r1" pos="-0.15 0.15 0"/>
    <site name="r2" pos="-0.15 -0.15 0"/><site name="r3" pos="0.15 -0.15 0" euler="0 0 1"/>
    <geom type="sphere" size="0.03" pos="0.15 0.15 0" mass="0.05"/>
    <geom type="sphere" size="0.03" pos="-0.15 0.15 0" mass="0.05"/>
    <geom type="sphere" size="0.03" pos="-0.15 -0.15 0" mass="0.05"/>
    <geom type="sphere" size="0.03" pos="0.15 -0.15 0" mass="0.05"/>
  </body></worldbody>
  <actuator>
    <motor name="t0" site="r0" gear="0 0 1 0 0 0" ctrllimited="true" ctrlrange="0 10"/>
    <motor name="t1" site="r1" gear="0 0 1 0 0 0" ctrllimited="true" ctrlrange="0 10"/>
    <motor name="t2" site="r2" gear="0 0 1 0 0 0" ctrllimited="true" ctrlrange="0 10"/>
    <motor name="t3" site="r3" gear="0 0 1 0 0 0" ctrllimited="true" ctrlrange="0 10"/>
  </actuator></mujoco>"""


def test_drone_hovers_and_climbs_like_mujoco(tmp_path):
    """A free body with four thrusters (site transmission, gear along the site's z): MuJoCo's
    hover control m g / 4 per rotor holds it (height change < 1e-3 m over 1 s), a larger one
    climbs as in MuJoCo."""
    import mujoco

    path = tmp_path / "drone.xml"
    path.write_text(_DRONE)
    result = load_mjcf_quietly(path)
    assert result.actuator_names == ["t0", "t1", "t2", "t3"]
    assert result.actuator_ids.tolist() == [0, 1, 2, 3]
    assert any("RobotWorld" in note and "'t3'" in note for note in result.notes)
    model = result.model
    mass = float(model.body_subtreemass[1])
    assert mass == pytest.approx(1.0)
    hover = mass * 9.81 / 4
    # climbing at 1.5 hover: ½ (g/2) t² = 2.45 m after 1 s
    for u, lo, hi in [(hover, -1e-3, 1e-3), (1.5 * hover, 2.4, 2.5)]:
        world = result.make_world(integrator="bdf2")
        data = mujoco.MjData(model)
        model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
        data.ctrl[:] = u
        world.ctrl[:] = data.ctrl[result.actuator_ids]
        z0 = world.pose(0)[0][2]
        heights = []
        for _ in range(500):  # 1 s
            world.step()
            mujoco.mj_step(model, data)
            heights.append((world.pose(0)[0][2] - z0, data.qpos[2] - 1.0))
        rise, mj_rise = np.array(heights).T
        assert lo < rise[-1] < hi, rise[-1]
        assert np.abs(rise - mj_rise).max() < 1e-3, np.abs(rise - mj_rise).max()
        # The thrust is along the body: no tilt appears under symmetric control.
        assert np.abs(result.qpos_from_world(world)[3:] - data.qpos[3:]).max() < 1e-6
