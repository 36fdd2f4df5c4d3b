"""abdsim validate on the bundled scene: numbers, outputs, a deliberately wrong model, bad input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from abdsim.validation import Tolerances, validate
from abdsim.validation.scenes import default_scene

FREE_FLIGHT = 1.2  # s: the bundled scene's first contact is at ~1.29 s


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    out = tmp_path_factory.mktemp("validate")
    return validate(duration=FREE_FLIGHT, dt=1e-3, out=out, progress=False)


def test_default_scene_passes_and_agrees_with_peers(result):
    assert result.passed, [c.as_dict() for c in result.failed]
    # inertia tables agree to 1e-9 (exact mass properties from the MJCF)
    inertia = [c for c in result.checks if c.name.startswith("inertia")]
    assert len(inertia) == 7
    assert max(c.value for c in inertia) < 1e-9
    # free flight: positions within 1e-4 m of MuJoCo RK4 and Pinocchio RK4 over 1.2 s
    ff = result.metrics["free_flight"]["bodies"]
    assert set(ff) == {"tbar", "brick", "ball", "can", "pill", "egg", "wedge"}
    for body in ff.values():
        assert body["position_error_mujoco"] < 1e-4
        assert body["position_error_pinocchio"] < 1e-4
        # the two references agree with each other far more tightly than with abdsim
        assert body["mujoco_vs_pinocchio"] < 1e-8
        assert body["orientation_error_mujoco"] < 5e-3


def test_free_flight_follows_ballistic_closed_form(result):
    """Centres of mass fly on parabolas: check abdsim against the closed form directly."""
    abd = result.trajectories["abdsim"]
    mj = result.trajectories["mujoco"]
    t = abd.time
    # MuJoCo RK4 is exact for a parabola: use its initial COM velocity
    m = np.array([r["mass"] for r in result.metrics["inertia"]])
    v0 = mj.linear_momentum[0] / m[:, None]
    c0 = mj.com[0]
    g = np.array([0.0, 0.0, -9.81])
    expected = c0[None] + t[:, None, None] * v0[None] + 0.5 * t[:, None, None] ** 2 * g
    assert np.abs(abd.com - expected).max() < 2e-5


def test_outputs_exist_and_parse(result):
    import jsonschema
    import matplotlib.image as mpimg

    from abdsim.validation.report import METRICS_SCHEMA

    out = result.out_dir
    report = (out / "report.md").read_text()
    assert "PASSED" in report and "tbar" in report and "![free-flight errors]" in report
    metrics = json.loads((out / "metrics.json").read_text())
    jsonschema.validate(metrics, METRICS_SCHEMA)
    assert metrics["passed"] is True
    for name in ("heights.png", "free_flight.png", "conservation.png"):
        img = mpimg.imread(out / name)
        assert img.shape[0] > 200 and img.shape[1] > 200
        assert img[..., :3].std() > 0.01  # not a blank image


def test_mcap_holds_both_simulators_poses(result):
    from abdsim.bridges import read_log

    mj = result.trajectories["mujoco"]
    ref = read_log(result.out_dir / "run.mcap", namespace="/mujoco")
    assert ref.names == mj.names
    np.testing.assert_allclose(ref.transforms, mj.extra["transforms"], atol=1e-12)
    abd = read_log(result.out_dir / "run.mcap", namespace="/abdsim")
    assert abd.transforms.shape[0] == result.trajectories["abdsim"].steps + 1
    np.testing.assert_allclose(abd.times[-1], FREE_FLIGHT, atol=1e-9)


def test_perturbed_inertia_fails_and_names_the_body(tmp_path):
    res = validate(
        duration=0.6,
        dt=1e-3,
        out=tmp_path,
        progress=False,
        mcap=False,
        perturb_inertia={"brick": 1.05},
    )
    assert not res.passed
    bodies = {c.body for c in res.failed}
    assert "brick" in bodies
    assert bodies <= {"brick", "all"}
    report = (tmp_path / "report.md").read_text()
    assert "FAILED" in report and "**brick**" in report


def test_cli_exit_status(tmp_path):
    from abdsim.cli import main

    assert (
        main(
            ["validate", "--duration", "0.3", "--quiet", "--no-mcap", "--out", str(tmp_path / "ok")]
        )
        == 0
    )
    assert (
        main(
            [
                "validate",
                "--duration",
                "0.3",
                "--quiet",
                "--no-mcap",
                "--out",
                str(tmp_path / "bad"),
                "--perturb-inertia",
                "tbar=1.1",
            ]
        )
        == 1
    )


def test_tolerance_file(tmp_path):
    good = tmp_path / "tol.json"
    good.write_text(json.dumps({"free_flight_position": 1e-12}))
    res = validate(
        duration=0.3, out=tmp_path / "strict", tolerances=good, progress=False, mcap=False
    )
    assert not res.passed
    assert all(c.name.startswith("free-flight position") for c in res.failed)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"free_flight_positon": 1e-3}))
    with pytest.raises(ValueError, match="unknown tolerance key.*free_flight_positon") as err:
        Tolerances.from_file(bad)
    assert "free_flight_position" in str(err.value)  # lists the valid keys


def test_bad_scenes(tmp_path):
    with pytest.raises(ValueError, match="unknown scene file type"):
        (tmp_path / "scene.obj").write_text("v 0 0 0\n")
        validate(tmp_path / "scene.obj", out=tmp_path)
    with pytest.raises(FileNotFoundError):
        validate(tmp_path / "missing.xml", out=tmp_path)
    static = tmp_path / "static.xml"
    static.write_text('<mujoco><worldbody><geom type="box" size="1 1 1"/></worldbody></mujoco>')
    with pytest.raises(ValueError, match="nothing dynamic"):
        validate(static, out=tmp_path, progress=False)
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody><body><geom type='box'></worldbody></mujoco>")
    with pytest.raises(ValueError):
        validate(broken, out=tmp_path, progress=False)


def test_default_scene_is_bundled():
    assert default_scene().is_file()
    assert Path(default_scene()).name == "tossed_bodies.xml"


def test_speed_is_one_convention_reported_stepping_and_end_to_end(result):
    from abdsim.validation.speed import speed_vs_mujoco

    t = result.metrics["timing"]
    abd, mj = t["simulators"]["abdsim"], t["simulators"]["mujoco"]
    # N× MuJoCo's speed, > 1 is faster: MuJoCo's wall time over abdsim's for the same steps.
    assert abd["steps"] == mj["steps"]
    assert t["speed_vs_mujoco"] == pytest.approx(mj["wall_time"] / abd["wall_time"], rel=1e-9)
    assert t["speed_vs_mujoco_end_to_end"] == pytest.approx(
        mj["end_to_end_wall_time"] / abd["end_to_end_wall_time"], rel=1e-9
    )
    for sim in t["simulators"].values():  # the whole run contains its steps
        assert sim["end_to_end_wall_time"] >= sim["wall_time"] > 0
    assert speed_vs_mujoco(2000.0, 1000.0) == 2.0  # twice MuJoCo's steps/s: 2× its speed
    report = (result.out_dir / "report.md").read_text()
    assert (
        f"abdsim runs at {t['speed_vs_mujoco']:.2f}× MuJoCo's speed (> 1 is faster), stepping only"
        in report
    )
    assert (
        f"{t['speed_vs_mujoco_end_to_end']:.2f}× MuJoCo's speed (> 1 is faster), end to end"
        in report
    )
    assert "time ratio" not in report
