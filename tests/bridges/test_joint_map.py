"""MuJoCo qpos/qvel and Pinocchio q/v against abdsim's joint coordinates, both ways, through
the sources' own forward kinematics: hinge offsets from a keyframe, ball quaternions loaded
away from identity, free bodies, Pinocchio's continuous joints and free-flyer root."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from abdsim.bridges import load_mjcf, load_urdf

_MJCF = """<mujoco><option timestep="0.001"/><worldbody>
  <body name="base" pos="0 0 1"><joint name="hinge" type="hinge" axis="0 1 0"/>
    <geom type="box" size="0.1 0.1 0.05"/>
    <body name="arm" pos="0 0 -0.3"><joint name="ball" type="ball"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.04"/>
      <body name="tip" pos="0 0 -0.35"><joint name="slide" type="slide" axis="1 0 0"/>
        <geom type="sphere" size="0.05"/></body></body></body>
  <body name="puck" pos="1 0 1"><freejoint name="free"/><geom type="box" size="0.1 0.08 0.06"/>
  </body></worldbody>
  <keyframe><key qpos="0.4  0.9 0.1 0.3 0.2  0.05  1 0.2 1.1 0.8 0.1 -0.5 0.3"
                 qvel="0.5  0.1 -0.2 0.3  0.4  0.1 0.2 -0.3 0.6 -0.4 0.2"/></keyframe>
</mujoco>"""


def _quat_close(a, b) -> float:
    return min(np.abs(a - b).max(), np.abs(a + b).max())


def _mjcf_result(tmp_path):
    path = tmp_path / "chain.xml"
    path.write_text(_MJCF)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_mjcf(path)


def test_mjcf_qpos_qvel_round_trip_through_mujoco_kinematics(tmp_path):
    result = _mjcf_result(tmp_path)
    assert result.joint_names == ["hinge", "ball", "slide"]  # the free joint is a body's state
    world = result.make_world(contact=False)
    # At load: every joint coordinate is 0 (identity quaternion) and qpos is the keyframe's.
    np.testing.assert_allclose(world.joint_positions(), [0, 1, 0, 0, 0, 0], atol=1e-12)
    load = np.array(result.model.key_qpos[0])
    qpos_load = result.qpos_from_world(world)
    assert np.abs(qpos_load[:5] - load[:5]).max() < 1e-12
    assert _quat_close(qpos_load[1:5], load[1:5] / np.linalg.norm(load[1:5])) < 1e-12
    # The keyframe's qvel is the bodies' initial velocity, read back through the mapping.
    np.testing.assert_allclose(result.qvel_from_world(world), result.model.key_qvel[0], atol=1e-9)
    rng = np.random.default_rng(3)
    qpos = load + rng.normal(scale=0.3, size=load.size)
    for adr in (1, 9):  # ball and free quaternions
        qpos[adr : adr + 4] /= np.linalg.norm(qpos[adr : adr + 4])
    qvel = rng.normal(size=result.model.nv)
    result.set_world_state(world, qpos, qvel)  # MuJoCo's kinematics places the bodies
    got = result.qpos_from_world(world)
    for sl in (slice(0, 1), slice(5, 9)):
        np.testing.assert_allclose(got[sl], qpos[sl], atol=1e-10)
    for adr in (1, 9):
        assert _quat_close(got[adr : adr + 4], qpos[adr : adr + 4]) < 1e-10
    np.testing.assert_allclose(result.qvel_from_world(world), qvel, atol=1e-9)
    # The joint-coordinate arrays alone (no world), both ways.
    jp = result.joint_positions_from_qpos(qpos)
    np.testing.assert_allclose(jp, world.joint_positions(), atol=1e-10)
    back = result.qpos_from_joint_positions(jp)
    np.testing.assert_allclose(back[:1], qpos[:1], atol=1e-12)
    assert _quat_close(back[1:5], qpos[1:5]) < 1e-12
    jv = result.joint_velocities_from_qvel(qvel)
    np.testing.assert_allclose(jv, world.joint_velocities(), atol=1e-9)
    np.testing.assert_allclose(result.qvel_from_joint_velocities(jv)[:5], qvel[:5], atol=1e-12)


def test_mjcf_ball_chain_moves_like_mujoco(tmp_path):
    """The mapping read while the chain swings (ball loaded away from identity): within
    1e-3 of MuJoCo RK4 after 0.3 s."""
    import mujoco

    result = _mjcf_result(tmp_path)
    world = result.make_world(contact=False, integrator="bdf2")
    model = result.model
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    data.qpos[1:5] /= np.linalg.norm(data.qpos[1:5])
    for _ in range(300):
        world.step()
        mujoco.mj_step(model, data)
    got = result.qpos_from_world(world)
    assert np.abs(got[[0, 5]] - data.qpos[[0, 5]]).max() < 1e-3
    assert _quat_close(got[1:5], data.qpos[1:5]) < 1e-3
    assert np.abs(got[6:9] - data.qpos[6:9]).max() < 1e-3
    assert np.abs(data.qpos[:6] - model.key_qpos[0][:6]).max() > 0.05  # it moved


def test_pinocchio_q_v_round_trip_with_continuous_joints_and_free_flyer(robot_urdf):
    import pinocchio as pin

    path = robot_urdf("double_pendulum_description", "double_pendulum_continuous.urdf")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = load_urdf(path, floating_base=True, q=None)
    model = result.model
    assert [model.joints[j].nq for j in range(1, model.njoints)] == [7, 2, 2]
    world = result.make_world(contact=False)
    rng = np.random.default_rng(5)
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    v = rng.normal(size=model.nv)
    result.set_world_state(world, q, v)
    got = result.qpos_from_world(world)
    np.testing.assert_allclose(got[:3], q[:3], atol=1e-10)
    assert _quat_close(got[3:7], q[3:7]) < 1e-10  # x, y, z, w
    np.testing.assert_allclose(got[7:], q[7:], atol=1e-10)  # (cos, sin) pairs
    np.testing.assert_allclose(result.qvel_from_world(world), v, atol=1e-9)
    angles = result.joint_positions_from_qpos(q)
    np.testing.assert_allclose(angles, world.joint_positions(), atol=1e-10)


def test_mappings_need_an_articulated_load(tmp_path):
    path = tmp_path / "chain.xml"
    path.write_text(_MJCF)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = load_mjcf(path, kinematic=True)
    with pytest.raises(ValueError, match=r"chain\.xml: joint mappings need an articulated load"):
        result.joint_positions_from_qpos(result.q)
    articulated = _mjcf_result(tmp_path)
    with pytest.raises(ValueError, match="qpos: expected 13 values, got 3"):
        articulated.joint_positions_from_qpos([0.0, 0.0, 0.0])
