"""Scene files: the bundled default scene and file-type detection."""

from __future__ import annotations

from pathlib import Path

SCENE_DIR = Path(__file__).resolve().parent / "scenes"
if not SCENE_DIR.is_dir():  # an editable install runs this file from the repository
    SCENE_DIR = Path(__file__).resolve().parents[1] / "examples" / "scenes"
DEFAULT_SCENE = "tossed_bodies.xml"


def default_scene() -> Path:
    """The bundled default scene (free bodies tossed with spin onto a ground plane)."""
    return SCENE_DIR / DEFAULT_SCENE


#: Every bundled scene: free bodies in contact, bodies starting at rest on the ground, the
#: loaders' example (free bodies and a hinged paddle that abdsim holds kinematic; its
#: short contacts are found from every step, not from samples), the jointed double
#: pendulum (its hinges as exact joints) and a floating quadruped (dropped on its floor
#: under its position actuators: robot_drop_mjcf).
VALIDATION_SCENES = (
    "tossed_bodies.xml",
    "resting_bodies.xml",
    "free_bodies.xml",
    "double_pendulum.xml",
    "quadruped.xml",
)


def bundled_scenes() -> list[Path]:
    """The scenes ``abdsim validate --sweep`` runs by default."""
    return [SCENE_DIR / name for name in VALIDATION_SCENES]


def scene_kind(path: Path) -> str:
    """``"mjcf"`` or ``"urdf"``; ValueError for anything else, FileNotFoundError if missing."""
    if not path.is_file():
        raise FileNotFoundError(f"scene file not found: {path}")
    suffix = path.suffix.lower()
    if suffix in (".xml", ".mjcf"):
        return "mjcf"
    if suffix == ".urdf":
        return "urdf"
    raise ValueError(
        f"unknown scene file type {suffix!r} for {path}: expected an MJCF (.xml, .mjcf) or "
        "URDF (.urdf) file"
    )
