"""MJCF hinges as exact joints: the bundled double pendulum against MuJoCo (RK4) on the same
file, and the joint physics read from MJCF."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import abdsim
from abdsim.bridges import LoaderError, build_articulated_scene, load_mjcf, load_urdf


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


def test_body_on_two_hinges_loads_as_a_chain_of_joint_frames(tmp_path):
    """A body on two joints loads (bridges/_joint_frames.py): world -a-> frame -c-> body, one
    abdsim joint per MuJoCo joint. A scene is never built from a body that still has two
    joints (a kinematic load handed to build_articulated_scene): a LoaderError names the
    file, the body and its joints."""
    xml = """<mujoco><worldbody><body name="b" pos="0 0 1">
      <joint name="a" type="hinge" axis="1 0 0"/><joint name="c" type="hinge" axis="0 1 0"/>
      <geom type="box" size="0.05 0.05 0.2" pos="0 0 -0.25"/></body></worldbody></mujoco>"""
    path = tmp_path / "two.xml"
    path.write_text(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = load_mjcf(path)
        scripted = load_mjcf(path, kinematic=True)
    assert result.names == ["b", "b (joint frame after 'a')"]
    assert [(j.name, j.parent, j.child) for j in result.joints] == [("a", None, 1), ("c", 1, 0)]
    assert [j.name for j in result.scene.joints] == ["a", "c"]
    assert [b.kind for b in scripted.bodies] == ["kinematic"]
    with pytest.raises(LoaderError, match=r"two\.xml: body 'b' moves on 2 joints \('a'.*'c'"):
        build_articulated_scene(scripted, contact=False)


_URDF = """<?xml version="1.0"?><robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01"
    iyz="0" izz="0.01"/></inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry>
    </collision></link>
  {links}{joints}</robot>"""


def _urdf_link(name: str, z: float) -> str:
    return (
        f'<link name="{name}"><inertial><origin xyz="0 0 {z}"/><mass value="0.5"/><inertia '
        'ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.001"/></inertial><collision>'
        f'<origin xyz="0 0 {z}"/><geometry><box size="0.04 0.04 0.2"/></geometry></collision>'
        "</link>"
    )


def _urdf_joint(name, kind, parent, child, z, extra=""):
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0 0 {z}"/><axis xyz="1 0 0"/>{extra}</joint>'
    )


def test_urdf_joint_physics_are_read(tmp_path):
    """URDF <dynamics damping friction> and <limit lower upper> relative to the loaded q;
    continuous joints and an empty limit (lower == upper) have none; a loaded position on a
    limit moves the limit out with a note."""
    links = "".join(_urdf_link(n, -0.15) for n in ("a", "b", "c", "d"))
    joints = (
        _urdf_joint("hinge", "revolute", "base", "a", -0.1,
                    '<limit lower="-1" upper="1.5" effort="1" velocity="1"/>'
                    '<dynamics damping="0.3" friction="0.2"/>')
        + _urdf_joint("spin", "continuous", "a", "b", -0.35, '<dynamics damping="0.1"/>')
        + _urdf_joint("empty", "revolute", "b", "c", -0.35,
                      '<limit lower="0" upper="0" effort="1" velocity="1"/>')
        + _urdf_joint("slide", "prismatic", "c", "d", -0.35,
                      '<limit lower="0" upper="0.2" effort="1" velocity="1"/>')
    )  # fmt: skip
    path = tmp_path / "r.urdf"
    path.write_text(_URDF.format(links=links, joints=joints))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = load_urdf(path, q=[0.25, 1.0, 0.0, 0.0, 0.0])
        scene = result.scene
    assert result.joint_names == ["hinge", "spin", "empty", "slide"]
    hinge, spin, empty, slide = scene.joints
    assert hinge.kind == spin.kind == empty.kind == "revolute" and slide.kind == "prismatic"
    assert (hinge.damping, hinge.frictionloss) == (0.3, 0.2)
    assert hinge.limits == pytest.approx((-1.25, 1.25))  # relative to the loaded 0.25 rad
    assert spin.damping == 0.1 and spin.limits is None  # continuous
    assert empty.limits is None
    assert slide.limits == pytest.approx((-2e-3, 0.2))  # loaded on its lower limit
    messages = [str(w.message) for w in caught]
    assert any("'empty'" in m and "is empty" in m for m in messages)
    assert any("'slide'" in m and "lower 0 -> -0.002" in m for m in messages)
    # Pinocchio's q: the continuous joint as (cos, sin) of its angle (loaded at 0).
    q = result.qpos_from_joint_positions([0.1, 0.2, 0.0, 0.05])
    assert q == pytest.approx([0.35, np.cos(0.2), np.sin(0.2), 0.0, 0.05])
    abdsim.World(scene).step(3)
