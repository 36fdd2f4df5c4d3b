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


def suite_xml(name: str) -> Path:
    """The dm_control suite file ``name`` (skips the test when dm_control is missing)."""
    dm_control = pytest.importorskip("dm_control")
    return Path(dm_control.__file__).parent / "suite" / name


def load_mjcf_quietly(path, **kwargs):
    """``load_mjcf`` with its notes' warnings silenced (tests that check notes read them)."""
    import warnings

    from abdsim.bridges import load_mjcf

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_mjcf(path, **kwargs)


def worst_qpos_error(result, world, model, data, steps: int) -> float:
    """Step abdsim's ``world`` and MuJoCo's ``data`` together: the largest |qpos difference|."""
    import mujoco
    import numpy as np

    worst = 0.0
    for _ in range(steps):
        world.step()
        mujoco.mj_step(model, data)
        worst = max(worst, float(np.abs(result.qpos_from_world(world) - data.qpos).max()))
    return worst
