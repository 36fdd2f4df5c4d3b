"""Restitution per impact, and ``abdsim validate`` with matched contact dissipation.

The impact detector is checked on the closed-form trajectory of a ball bouncing with a known
coefficient; the bundled tossed and resting scenes are then validated against MuJoCo: with
the MJCF's solref damping ratio as abdsim's contact damping (the default), every body ends
within 2 cm of MuJoCo's height (undamped, the tossed bodies ended up to 60 cm apart)."""

from __future__ import annotations

import numpy as np
import pytest

from abdsim.validation import validate
from abdsim.validation.restitution import impacts, restitution_table
from abdsim.validation.scenes import default_scene

G = 9.81


def bouncing_vz(e: float, v0: float, dt: float, seconds: float) -> np.ndarray:
    """Vertical velocity samples of a point dropped at −v0 onto the ground at t = 0.0137 s,
    each impact instantaneous with restitution e (closed form between impacts)."""
    t = np.arange(0.0, seconds, dt)
    vz = np.empty_like(t)
    t_hit, v_hit = 0.0137, -v0  # velocity just before the next impact
    v_start, t_start = -v0 + G * 0.0137, 0.0
    for i, ti in enumerate(t):
        while ti >= t_hit:
            v_start, t_start = -e * v_hit, t_hit
            t_hit = t_start + 2 * v_start / G if v_start > 0 else np.inf
            v_hit = -v_start
        vz[i] = v_start - G * (ti - t_start)
    return vz


@pytest.mark.parametrize("e", [0.0, 0.5, 0.9])
def test_impacts_measure_a_closed_form_bounce(e):
    dt = 1e-3
    vz = bouncing_vz(e, 3.0, dt, 1.0)
    found = impacts(vz, dt)
    assert len(found) >= 1
    # one sample of gravity on each side of the impact: |Δe| ≤ 2 g dt / v
    assert found[0]["restitution"] == pytest.approx(e, abs=2 * G * dt / 3.0)
    if e > 0:
        assert len(found) >= 2
        assert found[1]["restitution"] == pytest.approx(e, abs=2 * G * dt / (3.0 * e))
    assert restitution_table(["p"], vz[:, None], dt)["p"] == [i["restitution"] for i in found]


def test_free_fall_has_no_impact():
    t = np.arange(0.0, 1.0, 0.01)
    assert impacts(2.0 - G * t, 0.01) == []


@pytest.mark.parametrize(
    "scene,duration", [("tossed_bodies.xml", 2.5), ("resting_bodies.xml", 1.0)]
)
def test_validate_matches_mujoco_heights_with_matched_dissipation(tmp_path, scene, duration):
    path = default_scene().parent / scene
    r = validate(path, duration=duration, dt=1e-3, out=tmp_path, progress=False, mcap=False)
    assert r.passed, [c.as_dict() for c in r.failed]
    bodies = r.metrics["contact"]["bodies"]
    for name, b in bodies.items():
        assert abs(b["rest_height_abdsim"] - b["rest_height_mujoco"]) < 0.02, name
        assert isinstance(b["restitution_abdsim"], list)
        assert isinstance(b["restitution_mujoco"], list)
    if scene.startswith("tossed"):
        # every body lands at ~11 m/s; critically damped in both, the first impact keeps
        # little of it (measured: MuJoCo e = 0.10-0.13, abdsim 0-0.03; undamped, abdsim's
        # bodies bounced over a metre). Later, slower impacts of tumbling bodies are only reported.
        for name, b in bodies.items():
            e_mj, e_abd = b["restitution_mujoco"][0], b["restitution_abdsim"][0]
            assert e_mj < 0.2 and e_abd < 0.2, name
            assert abs(e_mj - e_abd) < 0.15, name
    assert "restitution per impact" in r.report.read_text()
