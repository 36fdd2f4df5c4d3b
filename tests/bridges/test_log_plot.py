"""``abdsim log plot``: units on the axes, two namespaces of one body overlaid."""

from __future__ import annotations

import numpy as np
import pytest

from abdsim.bridges import McapLogger
from abdsim.bridges.log_plot import log_figure
from abdsim.cli import main


@pytest.fixture
def two_namespaces(tmp_path):
    path = tmp_path / "both.mcap"
    T = np.tile(np.eye(4), (2, 1, 1))
    with McapLogger(path, names=["ball", "box"]) as log:
        log.add_bodies(["ball", "box"], namespace="/mujoco")
        for k in range(30):
            t = 0.01 * k
            T[:, 2, 3] = 2.0 - 0.5 * 9.81 * t**2
            log.log_state(t, T)
            log.log_diagnostics(t, {"newton_iterations": 2, "wall_time": 1e-4})
            T2 = T.copy()
            T2[:, 2, 3] += 0.01  # the reference 1 cm higher
            log.log_state(t, T2, namespace="/mujoco")
    return path


def test_overlay_of_two_namespaces_for_one_body(two_namespaces):
    fig = log_figure(
        two_namespaces, bodies=["ball"], field="position", namespaces=["/abdsim", "/mujoco"]
    )
    (ax,) = fig.axes
    assert ax.get_xlabel() == "simulated time [s]" and ax.get_ylabel() == "position [m]"
    lines = {line.get_label(): line for line in ax.get_lines()}
    assert set(lines) == {f"{ns} ball {c}" for ns in ("/abdsim", "/mujoco") for c in "xyz"}
    z_abd, z_mj = lines["/abdsim ball z"], lines["/mujoco ball z"]
    t = 0.01 * np.arange(30)
    np.testing.assert_allclose(z_abd.get_ydata(), 2.0 - 0.5 * 9.81 * t**2, rtol=0, atol=1e-15)
    np.testing.assert_allclose(z_mj.get_ydata() - z_abd.get_ydata(), 0.01, atol=1e-12)
    assert z_abd.get_linestyle() != z_mj.get_linestyle()
    assert z_abd.get_color() == z_mj.get_color()  # one colour per component


@pytest.mark.parametrize(
    ("options", "ylabel"),
    [
        ({"bodies": ["box"], "field": "velocity"}, "linear velocity, world frame [m/s]"),
        ({"bodies": ["box"], "field": "angular_velocity"}, "angular velocity, world frame [rad/s]"),
        ({"diagnostic": "wall_time"}, "wall_time [s]"),
        ({"diagnostic": "newton_iterations"}, "newton_iterations [count]"),
    ],
)
def test_every_plot_has_units(two_namespaces, options, ylabel):
    (ax,) = log_figure(two_namespaces, **options).axes
    assert ax.get_ylabel() == ylabel and ax.get_xlabel() == "simulated time [s]"


def test_cli_overlay(two_namespaces, tmp_path):
    out = tmp_path / "ball.png"
    argv = ["log", "plot", str(two_namespaces), "--body", "ball", "--namespace", "/abdsim"]
    assert main([*argv, "--namespace", "/mujoco", "-o", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
