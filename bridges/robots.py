"""Where the example robots are: the URDFs of the ``example-robot-data`` wheel.

That wheel installs data only (``import example_robot_data`` fails): its robots sit under
``site-packages/cmeel.prefix/share/example-robot-data/robots/<x>_description/urdf/``.
"""

from __future__ import annotations

import sys
from pathlib import Path

_SUBDIR = Path("cmeel.prefix") / "share" / "example-robot-data" / "robots"


def _robots_dir() -> Path:
    for entry in sys.path:
        candidate = Path(entry or ".") / _SUBDIR
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(
        "example-robot-data is not installed (pip install example-robot-data): no "
        f"{_SUBDIR} on sys.path"
    )


def example_robots() -> dict[str, Path]:
    """Every example robot URDF by name (its file name without ``.urdf``), sorted."""
    found = sorted(_robots_dir().glob("*/urdf/*.urdf"))
    return {p.stem: p for p in found}


def example_robot(name: str) -> Path:
    """The URDF of an example robot, e.g. ``example_robot("panda")``.

    ``name`` is a URDF file name without ``.urdf`` (``"panda"``, ``"ur5_robot"``,
    ``"solo12"``) or a description folder without ``_description`` whose folder holds one
    URDF of that name. :func:`example_robots` lists them all.

    Raises:
        FileNotFoundError: example-robot-data is missing, or no robot is called ``name``
            (the message lists the close names).
    """
    robots = example_robots()
    if name in robots:
        return robots[name]
    folder = _robots_dir() / f"{name}_description" / "urdf"
    urdfs = sorted(folder.glob("*.urdf")) if folder.is_dir() else []
    if len(urdfs) == 1:
        return urdfs[0]
    close = [n for n in robots if name.lower() in n.lower()] or list(robots)
    raise FileNotFoundError(f"no example robot {name!r}; try one of: {', '.join(close[:20])}")
