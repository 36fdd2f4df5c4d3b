"""Every code block of README.md runs as written.

Python blocks run each in a fresh interpreter, bash blocks in bash (``set -e -o pipefail``),
in README order, in one scratch folder that holds a link to ``examples/`` (the README's
relative paths start at the repository root). Blocks that install abdsim (``pip install``)
are what CI itself runs (``.ci/run``) and are not repeated here.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```$", re.S | re.M)


def readme_blocks() -> list[tuple[str, str]]:
    return [(lang, code) for lang, code in BLOCK.findall((ROOT / "README.md").read_text())]


def test_the_readme_has_runnable_blocks():
    langs = [lang for lang, _ in readme_blocks()]
    assert langs.count("python") >= 5 and "bash" in langs


def test_every_readme_block_runs(tmp_path):
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    env = {**os.environ, "MPLBACKEND": "Agg"}
    bindir = str(Path(sys.executable).parent)  # the `abdsim` script of this environment
    env["PATH"] = bindir + os.pathsep + env.get("PATH", "")
    ran = 0
    for i, (lang, code) in enumerate(readme_blocks()):
        if lang == "python":
            cmd = [sys.executable, "-c", code]
        elif lang == "bash" and "pip install" not in code:
            cmd = ["bash", "-e", "-o", "pipefail", "-c", code]
        else:
            continue
        proc = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True)
        if proc.returncode != 0:
            pytest.fail(f"README block {i} ({lang}) failed:\n{code}\n--- stderr ---\n{proc.stderr}")
        assert "Traceback" not in proc.stderr, f"README block {i} printed a traceback"
        ran += 1
    assert ran >= 6
    # What the blocks say they write is there, under the output folder.
    for name in ("run.mcap", "more.mcap", "box.png", "validation/report.md"):
        assert (tmp_path / "abdsim_out" / name).is_file(), name
    assert sorted(p.name for p in tmp_path.iterdir()) == ["abdsim_out", "examples"]
