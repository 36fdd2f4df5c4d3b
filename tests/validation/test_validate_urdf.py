"""abdsim validate on URDF robots: mass properties against Pinocchio and MuJoCo (part of every
robot's report; the motion is tested in test_robot_validation.py)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from abdsim.validation import validate

DATA = Path(__file__).resolve().parents[1] / "bridges" / "data"


def robots_dir() -> Path | None:
    import sys

    for entry in sys.path:
        candidate = Path(entry or ".") / "cmeel.prefix/share/example-robot-data/robots"
        if candidate.is_dir():
            return candidate
    return None


def inertia_checks(res) -> list:
    return [c for c in res.checks if c.name.startswith("inertia")]


def test_test_arm_inertias_match_both_peers(tmp_path):
    res = validate(DATA / "arm.urdf", duration=0.05, out=tmp_path, progress=False)
    assert all(c.passed for c in inertia_checks(res))
    refs = {(r["reference"], r["body"]) for r in res.metrics["inertia"]}
    assert refs == {
        ("Pinocchio", "arm"),
        ("Pinocchio", "finger"),
        ("MuJoCo", "arm"),
        ("MuJoCo", "finger"),
    }
    assert max(c.value for c in inertia_checks(res)) < 1e-9
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["settings"]["mode"] == "robot"
    assert "| inertia vs MuJoCo | finger |" in (tmp_path / "report.md").read_text()


@pytest.mark.parametrize(
    "robot",
    ["double_pendulum_description/urdf/double_pendulum.urdf", "ur_description/urdf/ur5_robot.urdf"],
)
def test_example_robot_data(robot, tmp_path):
    base = robots_dir()
    if base is None:
        pytest.skip("example-robot-data is not installed")
    res = validate(base / robot, duration=0.05, out=tmp_path, progress=False)
    assert all(c.passed for c in inertia_checks(res)), [c.as_dict() for c in res.failed]
    references = {r["reference"] for r in res.metrics["inertia"]}
    assert references == {"Pinocchio", "MuJoCo"}  # package:// meshes resolved for MuJoCo


def test_malformed_urdf(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='r'><link name='a'>")
    with pytest.raises(ValueError):
        validate(bad, out=tmp_path / "out", progress=False)
