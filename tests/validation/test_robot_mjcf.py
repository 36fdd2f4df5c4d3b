"""``abdsim validate`` on a jointed MJCF robot compares joint velocities as well as positions
with MuJoCo RK4 (the bundled double pendulum)."""

from __future__ import annotations

from pathlib import Path

import pytest

from abdsim.validation import validate
from abdsim.validation.tolerances import Tolerances

SCENE = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "double_pendulum.xml"


def test_joint_velocities_follow_mujoco(tmp_path):
    res = validate(SCENE, duration=0.5, dt=1e-3, out=tmp_path, progress=False, mcap=False)
    speed = {c.body: c.value for c in res.checks if c.name == "joint velocity vs MuJoCo RK4"}
    assert set(speed) == {"shoulder", "elbow"}
    assert max(speed.values()) < 1e-2  # measured 0.6 and 1.8 mrad/s over 1 s
    assert res.metrics["joints"]["elbow"]["max_velocity_error"] == speed["elbow"]


def test_a_tight_velocity_tolerance_fails_and_names_the_joints(tmp_path):
    tol = Tolerances(joint_velocity=1e-9)
    res = validate(SCENE, duration=0.1, dt=1e-3, out=tmp_path, tolerances=tol, progress=False)
    assert {(c.name, c.body) for c in res.failed} == {
        ("joint velocity vs MuJoCo RK4", "shoulder"),
        ("joint velocity vs MuJoCo RK4", "elbow"),
    }


def test_floating_is_for_urdf_robots(tmp_path):
    """An MJCF robot with a free root is dropped without --floating
    (test_robot_drop_mjcf.py); the flag itself is the URDF's."""
    with pytest.raises(ValueError, match="--floating applies to URDF robots"):
        validate(SCENE, out=tmp_path / "out", progress=False, floating=True)
