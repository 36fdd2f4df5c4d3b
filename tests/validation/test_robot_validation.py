"""``abdsim validate robot.urdf``: example-robot-data's UR5 (fixed base, zero torque) against
Pinocchio (ABA + RK4) and MuJoCo (RK4), and every check of the report seen failing on a
deliberately wrong model."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from abdsim.cli import main
from abdsim.validation import validate
from abdsim.validation.robot_validation import validate_robot
from abdsim.validation.tolerances import Tolerances


def robot_file(relative: str) -> Path:
    for entry in sys.path:
        path = Path(entry or ".") / "cmeel.prefix/share/example-robot-data/robots" / relative
        if path.is_file():
            return path
    pytest.skip(f"example-robot-data's {relative} is not installed")


@pytest.fixture(scope="module")
def ur5() -> Path:
    return robot_file("ur_description/urdf/ur5_robot.urdf")


def by_name(res, name: str) -> dict[str, float]:
    return {c.body: c.value for c in res.checks if c.name == name}


def test_ur5_links_follow_pinocchio_at_default_settings(ur5, tmp_path):
    res = validate_robot(ur5, 0.5, 1e-3, tmp_path, Tolerances())
    links = by_name(res, "link position vs Pinocchio")
    assert len(links) == 6
    # The joints issue's 2 mm over 0.5 s at the default Newton tolerances: measured 0.10 mm
    # (1.1 mm before jointed bodies started Newton from the prediction plus the last correction).
    assert max(links.values()) < 2e-3, links
    assert res.metrics["joint_violation"]["position"] <= 1e-6
    assert res.metrics["joint_violation"]["angle"] <= 1e-6
    travel = [j["travel"] for j in res.metrics["joints"].values()]
    assert max(travel) > 0.5  # zero control: the arm fell


def test_ur5_passes_every_check_at_default_settings(ur5, tmp_path):
    res = validate(ur5, duration=0.5, dt=1e-3, out=tmp_path, progress=False)
    assert res.passed, [c.as_dict() for c in res.failed]
    assert res.metrics["settings"]["mode"] == "robot"
    position = by_name(res, "joint position vs Pinocchio")
    assert max(position.values()) < 1e-3  # measured 0.22 mrad
    assert max(by_name(res, "joint velocity vs MuJoCo RK4").values()) < 1e-2  # 2.2e-3
    assert {r["reference"] for r in res.metrics["inertia"]} == {"Pinocchio", "MuJoCo"}
    # the arm really fell (zero control) and all three agree on how
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["passed"] and "joints" in metrics
    for name in ("joints.png", "joint_velocities.png", "report.md", "ur5_robot.mujoco.urdf"):
        assert (tmp_path / name).is_file(), name


def test_every_robot_check_fails_on_a_wrong_model(ur5, tmp_path):
    """A heavier wrist link, an elbow 1 cm off its anchor and a wrist axis tilted by 10 mrad
    in abdsim only: each kind of check of the report fails somewhere."""
    res = validate(
        ur5,
        duration=0.2,
        dt=1e-3,
        out=tmp_path,
        progress=False,
        robot={
            "perturb_mass": {"wrist_1_link": 2.0},
            "perturb_anchor": {"elbow_joint": 0.01},
            "perturb_axis": {"wrist_2_joint": 0.01},
        },
    )
    kinds = {c.name for c in res.checks}
    assert kinds == {c.name for c in res.failed}, sorted(kinds - {c.name for c in res.failed})
    assert "inertia vs Pinocchio" in kinds and "joint violation (rad)" in kinds
    assert {c.body for c in res.failed if c.name.startswith("inertia")} == {"wrist_1_link"}
    assert "**no**" in res.report.read_text()


def test_command_line_reports_a_wrong_model(ur5, tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["validate", str(ur5), "--duration", "0.05", "--out", str(out), "--quiet"]
    assert main(argv + ["--perturb-mass", "forearm_link=3"]) == 1
    text = capsys.readouterr()
    assert "FAILED" in text.out and "forearm_link" in text.err
    assert main(argv + ["--kp", "10"]) == 1
    assert "--kp applies to the dropped robot: add --floating" in capsys.readouterr().err
    with pytest.raises(ValueError, match="no joint"):
        validate(
            ur5, duration=0.05, out=tmp_path, progress=False, robot={"perturb_anchor": {"x": 1}}
        )


WHEEL = """<?xml version="1.0"?>
<robot name="wheel">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
    </inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><origin xyz="0 0 0.2"/><mass value="0.5"/>
      <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.0005"/></inertial>
    <collision><origin xyz="0 0 0.2"/><geometry><box size="0.03 0.03 0.3"/></geometry></collision>
  </link>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="arm"/><origin xyz="0.15 0 0"/><axis xyz="1 0 0"/>
  </joint>
</robot>"""


def test_a_continuous_joint_swinging_through_pi(tmp_path):
    """A continuous joint (Pinocchio: cos, sin) released at 2 rad from upright swings down
    through π to 4.28 rad: compared unwrapped against both references."""
    path = tmp_path / "wheel.urdf"
    path.write_text(WHEEL)
    res = validate(
        path,
        duration=1.0,
        out=tmp_path / "out",
        progress=False,
        robot={"q": [np.cos(2.0), np.sin(2.0)]},
    )
    assert res.passed, [c.as_dict() for c in res.failed]
    spin = res.metrics["joints"]["spin"]
    assert spin["travel"] > np.pi - 2.0 + 1.0  # well past π
    assert spin["max_position_error_pinocchio"] < 1e-3  # measured 0.20 mrad at default settings


def test_the_panda_fingers_mimic_is_not_imposed_on_mujoco(tmp_path):
    """MuJoCo couples the Panda's fingers (URDF <mimic>) by an equality that abdsim and
    Pinocchio do not have: the twin drops it, with a note, and then follows Pinocchio
    (without it MuJoCo's fingers slid 0.22 m apart from Pinocchio's in 0.5 s)."""
    panda = robot_file("panda_description/urdf/panda.urdf")
    res = validate(panda, duration=0.3, out=tmp_path, progress=False)
    # Released mid-range (robot_setup.default_configuration) no joint reaches a limit, and
    # every check passes at default settings (measured: all joints within 2.6e-5 rad of both).
    assert res.passed, [c.as_dict() for c in res.failed]
    assert any("<mimic>" in note for note in res.metrics["notes"])
    joints = res.metrics["joints"]
    for name in ("panda_finger_joint1", "panda_finger_joint2"):
        gap = abs(
            joints[name]["max_position_error_mujoco"] - joints[name]["max_position_error_pinocchio"]
        )
        assert gap < 1e-5, (name, joints[name])
