"""``abdsim validate robot.xml`` on an MJCF robot with a free root (robot_drop_mjcf.py): the
bundled quadruped (3.2 kg, eight position actuators, kp = 20, kv = 0.4, armature 0.01, its
"stand" keyframe) dropped 5 cm onto its floor, dt = 2e-3, against MuJoCo RK4 on the same
file: base height, final stance, abdsim's gap and coal's; every check fails on a broken
setting or a wrong model; the controls that hold a keyframe stance differ between the
simulators by the loaded actuator length (abdsim's joints are relative to the loaded
configuration)."""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from abdsim.cli import main
from abdsim.validation import validate

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
QUADRUPED = SCENES / "quadruped.xml"
DT = 2e-3
G = 9.81


def drop(path, out, duration, **robot):
    return validate(path, duration=duration, dt=DT, out=out, progress=False, robot=robot)


def checks(res, name):
    return [c for c in res.checks if c.name == name]


def test_quadruped_stands_like_mujoco_after_one_second(tmp_path):
    res = drop(QUADRUPED, tmp_path, 1.0)
    assert res.passed, [c.as_dict() for c in res.failed]
    s = res.metrics["settings"]
    assert s["mode"] == "robot-drop" and s["stance"] == "keyframe 0 of quadruped.xml"
    assert s["kp"] is None  # the file's own actuators
    (height,) = checks(res, "base height vs MuJoCo at the end")
    assert height.value < 5e-3  # measured 1.4 mm (MuJoCo's soft floor: 7.5 mm penetration)
    z = res.metrics["base_height"]
    assert 0.2 < z["abdsim_end"] < 0.24  # fell from 5 cm above its 0.23 m stance and stands
    stance = {c.body: c.value for c in checks(res, "final stance vs MuJoCo")}
    assert len(stance) == 8 and max(stance.values()) < 1e-2  # measured 1.4 mrad
    gaps = res.metrics["gaps"]
    assert 0 < gaps["abdsim_min_gap"] < 2e-3  # landed: within d_hat of the floor
    assert gaps["coal_min_ground_gap"] > 0 and gaps["coal_intersecting_pairs"] == 0
    assert gaps["coal_min_pair_gap"] > 0  # the file's filter lets the legs collide: apart
    assert res.metrics["joint_violation"]["position"] <= 1e-6
    for name in ("base_height.png", "joints.png", "quadruped_drop.xml", "report.md"):
        assert (tmp_path / name).is_file(), name
    notes = "\n".join(res.metrics["notes"])
    assert "MuJoCo [0.5, -1.0, 0.5, -1.0" in notes and "abdsim [0.5, -1.0" in notes


def test_the_twin_lifts_only_the_root_to_the_drop_height(tmp_path):
    """Both simulators load the rewritten file; its lowest point is drop_height above the
    floor (MuJoCo's foot spheres: centre height minus radius), the stance is the file's."""
    import mujoco

    from abdsim.validation.robot_drop_mjcf import mjcf_drop_setup

    s = mjcf_drop_setup(QUADRUPED, tmp_path, DT, drop_height=0.08)
    mj, data = s.mj_model, s.mj_data
    feet = [mj.geom(f"{leg}_foot").id for leg in ("FL", "FR", "HL", "HR")]
    lowest = data.geom_xpos[feet, 2] - mj.geom_size[feet, 0]
    assert lowest == pytest.approx(0.08, abs=2e-3)  # abdsim's tessellated sphere vs MuJoCo's
    original = mujoco.MjModel.from_xml_path(str(QUADRUPED))
    np.testing.assert_array_equal(mj.key_qpos[0, 7:], original.key_qpos[0, 7:])
    assert mj.key_qpos[0, 2] == pytest.approx(original.key_qpos[0, 2] + 0.031, abs=2e-3)
    assert s.world.transforms()[s.base][2, 3] == pytest.approx(data.xpos[s.mj_base][2], abs=1e-12)


def test_every_drop_check_fails_on_a_broken_setting_or_a_wrong_model(tmp_path):
    """Without contact the robot falls through its floor (gap, coal and height checks fail);
    a hip joint 1 cm off its anchor and a knee axis tilted by 10 mrad fail the joint checks;
    a trunk ten times heavier sags: height and stance fail."""
    cases = {  # (duration, options)
        "through": (0.16, {"settings": {"contact": False}}),
        "joints": (0.2, {"perturb_anchor": {"FL_hip": 0.01}, "perturb_axis": {"HR_knee": 0.01}}),
        "heavy": (0.5, {"perturb_mass": {"trunk": 10.0}}),
    }
    runs = {k: drop(QUADRUPED, tmp_path / k, t, **options) for k, (t, options) in cases.items()}
    through, wrong_joints, heavy = runs["through"], runs["joints"], runs["heavy"]
    assert checks(through, "ground gap (coal)")[0].value < -0.05
    violations = {"joint violation (m)", "joint violation (rad)"}
    assert {c.name for c in wrong_joints.failed} == violations
    assert checks(heavy, "base height vs MuJoCo at the end")[0].value > 0.02  # measured 28 mm
    assert min(c.value for c in checks(heavy, "final stance vs MuJoCo")) > 0.1
    kinds = {c.name for c in through.checks}
    failed = {c.name for r in (through, wrong_joints, heavy) for c in r.failed}
    assert kinds == failed, sorted(kinds - failed)
    assert "**no**" in through.report.read_text()


def test_hold_controls_keep_a_keyframe_stance_in_both(tmp_path):
    """A general affine servo (gain 30, bias -45·L - 3·L̇, gear 2) and a motor, loaded at a
    keyframe: MuJoCo's actuator force is zero at its hold control, and the same control keeps
    abdsim's joints where they loaded; control 0 pulls the servo's joint like MuJoCo's (the
    loader folds b1·L0 into abdsim's actuator bias)."""
    import mujoco

    from abdsim.bridges import load_mjcf
    from abdsim.validation.robot_drop_mjcf import hold_controls

    xml = QUADRUPED.read_text()
    xml = re.sub(
        r"<actuator>.*</actuator>",
        '<actuator><general joint="FL_hip" gainprm="30" biastype="affine" biasprm="0 -45 -3" '
        'gear="2"/><motor joint="FL_knee"/></actuator>',
        xml,
        flags=re.S,
    ).replace('ctrl="0.5 -1 0.5 -1 0.5 -1 0.5 -1"', "")
    path = tmp_path / "servo.xml"
    path.write_text(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = load_mjcf(path)
    mj = result.model
    data = mujoco.MjData(mj)
    mujoco.mj_resetDataKeyframe(mj, data, 0)
    mujoco.mj_forward(mj, data)
    u_mj, u_abd = hold_controls(mj, data, result)
    assert u_mj == pytest.approx([45.0 / 30.0 * 2 * 0.5, 0.0])  # -b1/g · gear · q0
    assert u_abd == pytest.approx(u_mj)
    data.ctrl[:] = u_mj
    mujoco.mj_forward(mj, data)
    assert data.actuator_force == pytest.approx([0.0, 0.0], abs=1e-12)

    def hip_after(ctrl) -> float:
        world = result.make_world(contact=False, gravity=[0.0, 0.0, 0.0])
        world.ctrl[:] = ctrl
        world.step(50)
        return float(world.joint_positions()[0])

    assert abs(hip_after(u_abd)) < 1e-9  # no force: it stays at the loaded 0.5 rad
    assert hip_after([0.0, 0.0]) < -0.05  # target 0 rad: pulled back from 0.5


def test_a_robot_without_actuators_falls_with_zero_control(tmp_path):
    """No actuators and no keyframe: the qpos0 stance, zero controls, 30 ms of free fall
    from 5 cm in both (gap: 5 cm − g t²/2)."""
    xml = QUADRUPED.read_text()
    xml = re.sub(r"<actuator>.*</actuator>|<keyframe>.*</keyframe>", "", xml, flags=re.S)
    path = tmp_path / "limp.xml"
    path.write_text(xml)
    res = drop(path, tmp_path / "out", 0.03)
    assert res.passed, [c.as_dict() for c in res.failed]
    assert res.metrics["settings"]["stance"] == "qpos0 of limp.xml"
    assert "MuJoCo [], abdsim []" in "\n".join(res.metrics["notes"])
    gap = res.metrics["gaps"]["abdsim_min_gap"]
    assert gap == pytest.approx(0.05 - 0.5 * G * 0.03**2, abs=1e-3)


def test_command_line_drop_and_bad_input(tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["validate", str(QUADRUPED), "--dt", "2e-3", "--duration", "0.02", "--quiet"]
    assert main(argv + ["--out", str(out)]) == 0
    assert "PASSED" in capsys.readouterr().out
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["settings"]["mode"] == "robot-drop"
    with pytest.raises(ValueError, match=r"\['kp'\] apply to a URDF drop"):
        drop(QUADRUPED, tmp_path / "kp", 0.02, kp=5.0)
    floorless = tmp_path / "floorless.xml"
    floorless.write_text(re.sub(r'<geom name="floor"[^>]*/>', "", QUADRUPED.read_text()))
    with pytest.raises(ValueError, match="floorless.xml: .* it has none"):
        drop(floorless, tmp_path / "f", 0.02)
    two = tmp_path / "two.xml"
    limp = re.sub(r"<keyframe>.*</keyframe>", "", QUADRUPED.read_text(), flags=re.S)
    two.write_text(
        limp.replace(
            "<worldbody>",
            '<worldbody><body name="ball" pos="1 1 1"><freejoint/>'
            '<geom type="sphere" size="0.05"/></body>',
        )
    )
    with pytest.raises(ValueError, match="exactly one free joint .* has 2"):
        drop(two, tmp_path / "t", 0.02)
