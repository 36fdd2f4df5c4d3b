"""MJCF hinges as exact joints: the bundled double pendulum against MuJoCo (RK4) on the same
file, and the joint physics read from MJCF."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import abdsim
from abdsim.bridges import LoaderError, build_articulated_scene, load_mjcf


def test_double_pendulum_mjcf_matches_mujoco_rk4(scenes_dir):
    import mujoco

    path = scenes_dir / "double_pendulum.xml"
    result = load_mjcf(path, kappa=1e10)
    scene = build_articulated_scene(result, integrator="bdf2", contact=False)
    assert [j.name for j in scene.joints] == ["shoulder", "elbow"]
    world = abdsim.World(scene)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    q0 = data.qpos.copy()
    worst, violation = 0.0, 0.0
    for _ in range(1000):  # 1 s at the file's dt = 1e-3
        d = world.step()
        mujoco.mj_step(model, data)
        worst = max(worst, np.abs(q0 + world.joint_positions() - data.qpos).max())
        violation = max(violation, d.joint_violation)
    assert worst < 1e-3, worst
    assert violation <= 1e-6
    assert np.abs(data.qpos - q0).max() > 0.5  # it swung


def test_mjcf_joint_physics_are_read(tmp_path):
    xml = """<mujoco><compiler angle="radian"/><worldbody><body name="b" pos="0 0 1">
      <joint name="j" type="hinge" axis="1 0 0" damping="0.3" armature="0.05"
             frictionloss="0.2" stiffness="4" springref="0.1" limited="true" range="-1 1"/>
      <geom type="box" size="0.05 0.05 0.2" pos="0 0 -0.25"/></body></worldbody>
      <keyframe><key qpos="0.25"/></keyframe></mujoco>"""
    path = tmp_path / "hinge.xml"
    path.write_text(xml)
    scene = build_articulated_scene(load_mjcf(path), contact=False)
    (j,) = scene.joints
    assert (j.damping, j.armature, j.frictionloss, j.stiffness) == (0.3, 0.05, 0.2, 4.0)
    assert j.ref == pytest.approx(0.1 - 0.25)
    assert j.limits == pytest.approx((-1.25, 0.75))  # relative to the keyframe's 0.25 rad
    abdsim.World(scene).step(5)


def test_body_on_two_hinges_is_refused(tmp_path):
    """A body on two joints has no sound abdsim model: a LoaderError naming the file, the body
    and its joints, at load; ``kinematic=True`` still loads it (scripted)."""
    xml = """<mujoco><worldbody><body name="b" pos="0 0 1">
      <joint name="a" type="hinge" axis="1 0 0"/><joint name="c" type="hinge" axis="0 1 0"/>
      <geom type="box" size="0.05 0.05 0.2" pos="0 0 -0.25"/></body></worldbody></mujoco>"""
    path = tmp_path / "two.xml"
    path.write_text(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(LoaderError, match=r"two\.xml: body 'b' moves on 2 joints \('a'.*'c'"):
            load_mjcf(path)
        result = load_mjcf(path, kinematic=True)
    assert [b.kind for b in result.bodies] == ["kinematic"]
    with pytest.raises(LoaderError, match="body 'b' moves on 2 joints"):
        build_articulated_scene(result, contact=False)
