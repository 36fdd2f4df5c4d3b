"""abdsim validate on URDF robots: mass properties against Pinocchio and MuJoCo."""

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


def test_test_arm_inertias_match_both_peers(tmp_path):
    res = validate(DATA / "arm.urdf", out=tmp_path, progress=False)
    assert res.passed
    refs = {(r["reference"], r["body"]) for r in res.metrics["inertia"]}
    assert refs == {
        ("Pinocchio", "arm"),
        ("Pinocchio", "finger"),
        ("MuJoCo", "arm"),
        ("MuJoCo", "finger"),
    }
    assert max(c.value for c in res.checks) < 1e-9
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["settings"]["mode"] == "urdf-inertia"
    assert "fixed-base" in (tmp_path / "report.md").read_text()


@pytest.mark.parametrize(
    "robot",
    ["double_pendulum_description/urdf/double_pendulum.urdf", "ur_description/urdf/ur5_robot.urdf"],
)
def test_example_robot_data(robot, tmp_path):
    base = robots_dir()
    if base is None:
        pytest.skip("example-robot-data is not installed")
    res = validate(base / robot, out=tmp_path, progress=False)
    assert res.passed, [c.as_dict() for c in res.failed]
    references = {r["reference"] for r in res.metrics["inertia"]}
    assert references == {"Pinocchio", "MuJoCo"}  # package:// meshes resolved for MuJoCo


def test_malformed_urdf(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='r'><link name='a'>")
    with pytest.raises(ValueError):
        validate(bad, out=tmp_path / "out", progress=False)
