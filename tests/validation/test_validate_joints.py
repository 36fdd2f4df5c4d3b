"""``abdsim validate`` on a jointed MJCF: joint trajectories against MuJoCo RK4."""

from __future__ import annotations

import json
from pathlib import Path

from abdsim.validation import validate
from abdsim.validation.tolerances import Tolerances

SCENE = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "double_pendulum.xml"


def test_double_pendulum_validates_joint_by_joint(tmp_path):
    res = validate(SCENE, duration=0.5, dt=1e-3, out=tmp_path, progress=False, mcap=False)
    assert res.passed, [c.as_dict() for c in res.failed]
    by_joint = {c.body: c.value for c in res.checks if c.name.startswith("joint position")}
    assert set(by_joint) == {"shoulder", "elbow"}
    assert max(by_joint.values()) < 1e-3  # measured ~1e-4 rad
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["joint_violation"]["position"] <= 1e-6
    assert (tmp_path / "joints.png").is_file() and "shoulder" in res.report.read_text()


def test_a_tight_tolerance_fails_and_names_the_joint(tmp_path):
    tol = Tolerances(joint_position=1e-9)
    res = validate(SCENE, duration=0.2, dt=1e-3, out=tmp_path, tolerances=tol, progress=False)
    assert not res.passed
    assert {c.body for c in res.failed} == {"shoulder", "elbow"}
    assert "**no**" in res.report.read_text()
