"""``abdsim validate robot.urdf --floating``: example-robot-data's solo12 with a floating base,
dropped 5 cm onto the ground under position actuators holding its SRDF stance (kp = 5,
kv = 0.1 on all 12 joints, the same in MuJoCo), dt = 2e-3: base height against MuJoCo, gap
positive by abdsim and independently by coal. Both simulate robot–ground contacts; the
runs with abdsim's self-contact on (slower) are heavy (ABDSIM_HEAVY_TESTS=1)."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from abdsim.cli import main
from abdsim.validation import validate
from tests.validation.test_robot_validation import robot_file

HEAVY = os.environ.get("ABDSIM_HEAVY_TESTS") == "1"
SOLO12 = "solo_description/robots/solo12.urdf"
DT = 2e-3


@pytest.fixture(scope="module")
def solo12():
    return robot_file(SOLO12)


def drop(path, tmp_path, duration, **robot):
    return validate(
        path, duration=duration, dt=DT, out=tmp_path, progress=False, floating=True, robot=robot
    )


def checks(res, name):
    return [c for c in res.checks if c.name == name]


def test_solo12_stands_like_mujoco_after_one_second(solo12, tmp_path):
    res = drop(solo12, tmp_path, 1.0)
    assert res.passed, [c.as_dict() for c in res.failed]
    s = res.metrics["settings"]
    assert s["mode"] == "robot-drop" and s["stance"] == "solo.srdf standing"
    assert (s["kp"], s["kv"]) == pytest.approx((5.0, 0.1), rel=1e-3)  # 2.5 kg robot
    (height,) = checks(res, "base height vs MuJoCo at the end")
    assert height.value < 1e-2  # measured 5.4 mm (MuJoCo's soft floor: 6.6 mm penetration)
    z = res.metrics["base_height"]
    assert 0.15 < z["abdsim_end"] < 0.235  # landed from 5 cm above and stands, sagging a bit
    stance = [c.value for c in checks(res, "final stance vs MuJoCo")]
    assert len(stance) == 12 and max(stance) < 5e-2  # measured 26 mrad
    gaps = res.metrics["gaps"]
    assert 0 < gaps["abdsim_min_gap"] < 2e-3  # landed: within d_hat of the ground
    assert gaps["coal_min_ground_gap"] > 0 and gaps["coal_intersecting_pairs"] == 0
    assert res.metrics["joint_violation"]["position"] <= 1e-6
    assert (tmp_path / "base_height.png").is_file() and (tmp_path / "joints.png").is_file()


def test_every_drop_check_fails_on_a_wrong_model(solo12, tmp_path):
    """abdsim without contact (the robot falls through the floor) fails the gap, height and
    stance checks; one hip joint 1 cm off its anchor and one knee axis tilted by 10 mrad
    fail the joint-violation checks once the legs flex on landing."""
    through = drop(solo12, tmp_path / "a", 0.16, settings={"contact": False})
    assert checks(through, "ground gap (coal)")[0].value < -0.05
    wrong_joints = drop(
        solo12,
        tmp_path / "b",
        0.2,
        perturb_anchor={"FL_HAA": 0.01},
        perturb_axis={"HR_KFE": 0.01},
    )
    assert {c.name for c in wrong_joints.failed} == {
        "joint violation (m)",
        "joint violation (rad)",
    }
    kinds = {c.name for c in through.checks}
    failed = {c.name for c in through.failed + wrong_joints.failed}
    assert kinds == failed, sorted(kinds - failed)
    assert "**no**" in through.report.read_text()


def test_command_line_drop_with_given_gains(solo12, tmp_path, capsys):
    """20 ms of free fall from the command line: both fall alike, every check passes."""
    out = tmp_path / "out"
    argv = ["validate", str(solo12), "--floating", "--dt", "2e-3", "--duration", "0.02"]
    gains = ["--kp", "6", "--kv", "0.2", "--friction", "0.8"]
    assert main(argv + gains + ["--out", str(out), "--quiet"]) == 0
    assert "PASSED" in capsys.readouterr().out
    metrics = json.loads((out / "metrics.json").read_text())
    settings = metrics["settings"]
    assert (settings["kp"], settings["kv"], settings["friction"]) == (6.0, 0.2, 0.8)
    gaps = metrics["gaps"]
    assert gaps["abdsim_min_gap"] == pytest.approx(0.05 - 0.5 * 9.81 * 0.02**2, abs=2e-3)


@pytest.mark.skipif(not HEAVY, reason="heavy (self-contact): set ABDSIM_HEAVY_TESTS=1")
def test_self_contact_changes_nothing_in_a_stance(solo12, tmp_path):
    """abdsim's links also colliding with each other (not adjacent, not touching at load):
    nothing touches in a stance, so the drop ends where it does without, gap positive."""
    res = drop(solo12, tmp_path, 1.0, self_contact=True)
    assert res.passed, [c.as_dict() for c in res.failed]
    assert res.metrics["settings"]["self_contact"] is True
    gaps = res.metrics["gaps"]
    assert gaps["coal_min_pair_gap"] > 0 and gaps["coal_intersecting_pairs"] == 0


@pytest.mark.skipif(not HEAVY, reason="heavy (a second 1 s drop): set ABDSIM_HEAVY_TESTS=1")
def test_a_heavier_trunk_sags_and_fails_the_height_check(solo12, tmp_path):
    res = drop(solo12, tmp_path, 1.0, perturb_mass={"base_link": 3.0})
    (height,) = checks(res, "base height vs MuJoCo at the end")
    assert not height.passed
    assert np.isfinite(height.value)
