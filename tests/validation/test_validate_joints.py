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


def test_both_sides_run_without_contact(tmp_path):
    """A pendulum whose link swings through its floor: abdsim compares the articulation
    without contact, so MuJoCo's side must not collide either (regression: MuJoCo's link
    stopped on the floor while abdsim's swung on, and the joint failed by ~1 rad)."""
    path = tmp_path / "floor_pendulum.xml"
    path.write_text(
        """<mujoco><option timestep="0.001"/><worldbody>
  <geom name="floor" type="plane" size="2 2 0.1"/>
  <body name="link" pos="0 0 0.3"><joint name="swing" type="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.02"/></body></worldbody>
  <keyframe><key qpos="0.2"/></keyframe></mujoco>"""
    )
    res = validate(path, duration=0.5, dt=1e-3, out=tmp_path / "out", progress=False, mcap=False)
    assert res.passed, [c.as_dict() for c in res.failed]
    (angle,) = [c.value for c in res.checks if c.name.startswith("joint position")]
    assert angle < 1e-3
