"""The API reference (Sphinx autodoc over the docstrings) builds without a single warning."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def test_api_reference_builds_without_warnings(tmp_path):
    pytest.importorskip("sphinx")
    out = tmp_path / "html"
    cmd = [sys.executable, "-m", "sphinx", "-E", "-W", "--keep-going", "-q", "-b", "html"]
    # cwd outside the repository: `python -m` puts the working folder on sys.path, and the
    # source folder has no compiled core (the installed abdsim must be documented)
    proc = subprocess.run(
        [*cmd, str(ROOT / "docs" / "api"), str(out)], capture_output=True, text=True, cwd=tmp_path
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.strip() == ""
    core, bridges = (out / "core.html").read_text(), (out / "bridges.html").read_text()
    for anchor in ("abdsim.sim.world.World.pose", "abdsim.sim.world.World.twist"):
        assert f'id="{anchor}"' in core
    assert 'id="abdsim.bridges.robots.example_robot"' in bridges
