"""Shared fixtures of the bridges tests: example-robot-data URDFs, bundled scenes, test data."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data"
SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"


@pytest.fixture
def data_dir() -> Path:
    """tests/bridges/data."""
    return DATA


@pytest.fixture
def scenes_dir() -> Path:
    """examples/scenes."""
    return SCENES


def _robots_dir() -> Path | None:
    for entry in sys.path:
        candidate = Path(entry or ".") / "cmeel.prefix/share/example-robot-data/robots"
        if candidate.is_dir():
            return candidate
    return None


ROBOTS = _robots_dir()


@pytest.fixture
def robot_urdf():
    """A function (description, file) -> path of an example-robot-data URDF (else skip)."""

    def find(description: str, filename: str) -> Path:
        if ROBOTS is None:
            pytest.skip("example-robot-data is not installed")
        path = ROBOTS / description / "urdf" / filename
        if not path.is_file():
            pytest.skip(f"{path} not shipped by this example-robot-data")
        return path

    return find


@pytest.fixture
def rel_err():
    """A function (a, b) -> max |a - b| / max |b| (the relative error of a against b)."""
    import numpy as np

    def err(a, b) -> float:
        a, b = np.asarray(a, float), np.asarray(b, float)
        return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))

    return err
