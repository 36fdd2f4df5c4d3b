"""The ``abdsim`` command line: ``log info`` and ``log plot``."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from abdsim.bridges import McapLogger
from abdsim.cli import SUBCOMMANDS, build_parser, main


@pytest.fixture
def log_file(tmp_path):
    path = tmp_path / "run.mcap"
    T = np.tile(np.eye(4), (2, 1, 1))
    with McapLogger(path, names=["box", "ball"]) as log:
        for k in range(20):
            T[:, 2, 3] = 1.0 - 0.5 * 9.81 * (0.01 * k) ** 2
            log.log_state(0.01 * k, T)
            log.log_diagnostics(0.01 * k, {"newton_iterations": 2 + k % 3, "wall_time": 1e-4})
    return path


def test_log_info(log_file, capsys):
    assert main(["log", "info", str(log_file)]) == 0
    out = capsys.readouterr().out
    assert "/abdsim/tf" in out and "foxglove.FrameTransforms" in out
    assert "/abdsim/bodies" in out and "abdsim.BodyStates" in out
    assert "0.000000 .. 0.190000 s" in out
    assert "bodies /abdsim (2): box, ball" in out
    assert main(["log", "info", str(log_file), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    counts = {c["topic"]: c["messages"] for c in info["channels"]}
    assert counts["/abdsim/bodies"] == counts["/abdsim/tf"] == 20
    assert counts["/abdsim/diagnostics"] == 20


def test_log_plot_body_and_diagnostic(log_file, tmp_path, capsys):
    out = tmp_path / "ball.png"
    assert main(["log", "plot", str(log_file), "--body", "ball", "-o", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 10_000
    vel = tmp_path / "vel.png"
    assert (
        main(["log", "plot", str(log_file), "--body", "box", "--field", "velocity", "-o", str(vel)])
        == 0
    )
    assert vel.is_file()
    assert main(["log", "plot", str(log_file), "--diagnostic", "newton_iterations"]) == 0
    default = log_file.with_name("run-newton_iterations.png")
    assert default.is_file() and str(default) in capsys.readouterr().out


def test_cli_errors_are_clear_and_nonzero(log_file, tmp_path, capsys):
    assert main(["log", "plot", str(log_file), "--body", "nope"]) == 1
    assert "no body named 'nope'" in capsys.readouterr().err
    assert main(["log", "plot", str(log_file), "--diagnostic", "nope"]) == 1
    assert "available" in capsys.readouterr().err
    assert main(["log", "info", str(tmp_path / "missing.mcap")]) == 1
    assert "not found" in capsys.readouterr().err
    assert main([]) == 2
    with pytest.raises(SystemExit):
        main(["log", "plot", str(log_file), "--field", "colour"])


def test_subcommands_are_pluggable():
    assert SUBCOMMANDS["log"] == "abdsim.bridges.cli"
    commands = build_parser()._subparsers._group_actions[0].choices
    assert "log" in commands


def test_python_dash_m_abdsim(log_file):
    out = subprocess.run(
        [sys.executable, "-P", "-m", "abdsim", "log", "info", str(log_file)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert "bodies /abdsim (2): box, ball" in out
