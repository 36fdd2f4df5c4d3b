"""Importing abdsim from the repository folder either works or says in one line what to do."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import abdsim

SOURCE = Path(__file__).resolve().parents[2] / "abdsim"

# Drop an editable install's import hook, so the copied source folder shadows the installed
# abdsim exactly as the repository folder does for a plain `pip install .`.
SCRIPT = """
import sys
sys.meta_path[:] = [f for f in sys.meta_path if not type(f).__module__.startswith("_editable")]
import abdsim
"""


def test_source_folder_without_core_names_the_fix(tmp_path):
    shutil.copytree(SOURCE, tmp_path / "abdsim", ignore=shutil.ignore_patterns("*.so", "cpp"))
    (tmp_path / "abdsim" / "cpp").mkdir()  # what marks a source checkout
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT], cwd=tmp_path, capture_output=True, text=True, timeout=120
    )
    assert proc.returncode != 0
    last = proc.stderr.strip().splitlines()[-1]
    assert last.startswith("ImportError: this is abdsim's source folder (")
    assert str(tmp_path / "abdsim") in last and "pip install --no-build-isolation -e ." in last
    assert "circular import" not in proc.stderr


def test_installed_abdsim_has_its_core():
    assert abdsim._native._core.__name__ == "abdsim._core"


def test_core_kernels_leave_avx512_off():
    """README: native builds use the machine's instruction set but AVX-512 (GCC 12 warns
    through Eigen's AVX-512 packets, valgrind cannot run them)."""
    sets = abdsim._native._core.simd_instruction_sets()
    assert isinstance(sets, str) and sets
    assert "AVX512" not in sets
