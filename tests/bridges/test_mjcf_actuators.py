"""MJCF actuators on ``world.ctrl`` (bridges/_mjcf_actuators.py): every preset and a general
affine actuator, with gear, control and force ranges, against MuJoCo RK4 on the same model;
what is not modelled is named in the notes and left out of ``world.ctrl``."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from abdsim.bridges import load_mjcf

_ARM = """<mujoco><option timestep="0.001"/><worldbody>
  <body name="link" pos="0 0 1"><joint name="hinge" type="hinge" axis="0 1 0" damping="0.05"/>
    <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.04"/>
    <body name="slider" pos="0.5 0 0"><joint name="slide" type="slide" axis="1 0 0"/>
      <geom type="box" size="0.05 0.05 0.05"/></body></body></worldbody>
  <actuator>{actuators}</actuator></mujoco>"""

CASES = {
    "position": (
        '<position joint="hinge" kp="20" kv="1" gear="1.5" forcelimited="true" '
        'forcerange="-4 4"/><motor joint="slide"/>',
        [0.6, 0.0],
    ),
    "general": (  # gain 30, bias (0, -45, -3): a position servo with another gain ratio
        '<general joint="hinge" gainprm="30" biastype="affine" biasprm="0 -45 -3" gear="2"/>'
        '<general joint="slide" gainprm="4" biastype="affine" biasprm="0 0 -2"/>',
        [0.4, 0.3],
    ),
    "velocity": (
        '<velocity joint="hinge" kv="3" ctrllimited="true" ctrlrange="-1 1"/>'
        '<motor joint="slide" gear="-2" forcelimited="true" forcerange="-0.5 0.5"/>',
        [2.0, 1.0],  # the velocity control is clamped to 1, the slide force to 0.5
    ),
}


def _load(tmp_path, actuators: str, name: str = "arm.xml"):
    path = tmp_path / name
    path.write_text(_ARM.format(actuators=actuators))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_mjcf(path)


@pytest.mark.parametrize("case", sorted(CASES))
def test_actuated_arm_follows_mujoco_rk4(tmp_path, case):
    import mujoco

    actuators, ctrl = CASES[case]
    result = _load(tmp_path, actuators)
    assert result.actuator_ids.tolist() == [0, 1]
    assert len(result.scene.actuators) == 2
    world = result.make_world(contact=False, integrator="bdf2")
    model = result.model
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    data = mujoco.MjData(model)
    data.ctrl[:] = ctrl
    world.ctrl[:] = data.ctrl[result.actuator_ids]
    worst = 0.0
    for _ in range(1000):
        world.step()
        mujoco.mj_step(model, data)
        worst = max(worst, np.abs(result.qpos_from_world(world) - data.qpos).max())
    assert np.abs(data.qpos).max() > 0.1  # the actuators moved it
    assert worst < 5e-3, worst


def test_actuators_loaded_at_a_keyframe_follow_mujoco_rk4(tmp_path):
    """Loaded at a keyframe (hinge 0.5 rad, slide 0.1 m) abdsim's joint coordinates start at 0
    where MuJoCo's lengths are gear·qpos: a position servo with control 0 must pull the hinge
    back towards 0 as MuJoCo's does, and a constant bias b0 push the slide (regression: the
    servo held the loaded angle, 0.87 rad from MuJoCo after 0.3 s)."""
    import mujoco

    path = tmp_path / "key.xml"
    path.write_text(
        _ARM.format(
            actuators='<position joint="hinge" kp="20" kv="1" gear="1.5"/>'
            '<general joint="slide" gainprm="4" biastype="affine" biasprm="0.7 -6 -2"/>'
        ).replace("</mujoco>", '<keyframe><key qpos="0.5 0.1"/></keyframe></mujoco>')
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = load_mjcf(path)
    world = result.make_world(contact=False, integrator="bdf2")
    model = result.model
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    data.ctrl[:] = [0.0, 0.2]
    world.ctrl[:] = data.ctrl[result.actuator_ids]
    assert np.abs(result.qpos_from_world(world) - data.qpos).max() < 1e-12
    worst = 0.0
    for _ in range(300):
        world.step()
        mujoco.mj_step(model, data)
        worst = max(worst, np.abs(result.qpos_from_world(world) - data.qpos).max())
    assert abs(data.qpos[0] - 0.5) > 0.3  # MuJoCo's servo moved the hinge far from the key
    assert worst < 5e-3, worst


def test_unmodelled_actuators_are_named_and_left_out_of_ctrl(tmp_path):
    path = tmp_path / "bad.xml"
    path.write_text(
        _ARM.replace('<geom type="box"', '<site name="tip"/><geom type="box"').format(
            actuators='<motor name="ok" joint="hinge"/>'
            '<general name="filtered" joint="hinge" dyntype="filter" dynprm="0.1"/>'
            '<general name="unstable" joint="slide" biastype="affine" biasprm="0 2 0"/>'
            '<motor name="ref" site="tip" refsite="tip" gear="0 0 1 0 0 0"/>'
            '<motor name="thrust" site="tip" gear="0 0 1 0 0 0"/>'
        )
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = load_mjcf(path)
    assert res.actuator_names == ["ok", "thrust"]
    assert res.actuator_ids.tolist() == [0, 4]
    expected = {
        "filtered": "dyntype='filter'",
        "unstable": "destabilising bias",
        "ref": "refsite",
    }
    for name, why in expected.items():
        (note,) = [n for n in res.notes if n.startswith(f"actuator {name!r}")]
        assert why in note and "not in world.ctrl" in note
    assert sum(str(w.message).startswith("actuator ") for w in caught) == 3  # warned once each
    world = res.make_world(contact=False)
    assert world.ctrl.shape == (2,)
