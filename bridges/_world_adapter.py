"""The one place where bridges touch ``abdsim.Scene`` / ``abdsim.World``.

Loaders, drivers and the logger call these functions instead of the World's methods, so a
change of the World's API is absorbed here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass
class BodyDescription:
    """Name, kind and surface (body frame) of one body, for logging."""

    name: str
    kind: str
    vertices: np.ndarray
    triangles: np.ndarray


def _scene_class() -> Any:
    import abdsim

    scene = getattr(abdsim, "Scene", None)
    if scene is None:
        raise RuntimeError(
            "abdsim.Scene is not available in this version of abdsim: use "
            "result.geometries (one SimplicialComplex per body) and result.dt / gravity / "
            "grounds to build a scene by hand"
        )
    return scene


def build_scene(result: Any) -> Any:
    """A Scene with every body of a LoadResult, in order, and the result's settings."""
    scene = _scene_class()()
    for body in result.bodies:
        scene.add(body.geometry)
    return scene


# -- descriptions -----------------------------------------------------------------------------
def _expand(sc: Any, name: str, kind_of_instance) -> list[BodyDescription]:
    out = []
    n = sc.instance_count
    for k in range(n):
        label = name if n == 1 else f"{name}[{k}]"
        out.append(BodyDescription(label, kind_of_instance(sc, k), sc.positions, sc.triangles))
    return out


def _instance_kind(sc: Any, k: int) -> str:
    inst = sc.instances
    if "is_fixed" in inst and int(inst["is_fixed"][k]):
        return "fixed"
    return "dynamic"


def describe_bodies(source: Any) -> list[BodyDescription]:
    """Bodies of a LoadResult, a Scene / World, or a list of SimplicialComplexes."""
    from abdsim.bridges._bodies import LoadResult

    if isinstance(source, LoadResult):
        return [
            BodyDescription(b.name, b.kind, b.geometry.positions, b.geometry.triangles)
            for b in source.bodies
        ]
    geometries = _geometries_of(source)
    names = _names_of(source)
    out: list[BodyDescription] = []
    for i, sc in enumerate(geometries):
        out.extend(_expand(sc, f"body{i}" if names is None else "", _instance_kind))
    if names is not None:
        if len(names) != len(out):
            raise ValueError(f"{len(names)} body names for {len(out)} bodies")
        for d, name in zip(out, names, strict=True):
            d.name = name
    else:
        for i, d in enumerate(out):
            d.name = f"body{i}"
    return out


def _geometries_of(source: Any) -> list[Any]:
    if isinstance(source, (list, tuple)):
        return list(source)
    for holder in (source, getattr(source, "scene", None)):
        if holder is None:
            continue
        geoms = getattr(holder, "geometries", None)
        if geoms is not None:
            return list(geoms() if callable(geoms) else geoms)
    raise TypeError(
        f"cannot find the bodies of a {type(source).__name__}: pass a World, a Scene, a "
        "LoadResult or a list of SimplicialComplexes"
    )


def _names_of(source: Any) -> list[str] | None:
    for holder in (source, getattr(source, "scene", None)):
        names = getattr(holder, "body_names", None) if holder is not None else None
        if names is not None:
            return list(names() if callable(names) else names)
    return None


# -- world state ------------------------------------------------------------------------------
def world_time(world: Any) -> float:
    t = world.time
    return float(t() if callable(t) else t)


def world_dt(world: Any) -> float:
    for holder in (world, getattr(world, "scene", None), getattr(world, "settings", None)):
        dt = getattr(holder, "dt", None) if holder is not None else None
        if dt is not None:
            return float(dt() if callable(dt) else dt)
    raise AttributeError("cannot find the World's time step (dt)")


def world_step_count(world: Any) -> int | None:
    n = getattr(world, "step_count", None)
    if n is None:
        return None
    return int(n() if callable(n) else n)


def world_transforms(world: Any) -> np.ndarray:
    return np.asarray(world.transforms(), dtype=np.float64)


def world_velocities(world: Any) -> np.ndarray:
    v = getattr(world, "velocities", None)
    if v is None:
        return np.zeros_like(world_transforms(world))
    return np.asarray(v() if callable(v) else v, dtype=np.float64)


def world_diagnostics(world: Any) -> Any:
    d = getattr(world, "diagnostics", None)
    return d() if callable(d) else d


def world_step(world: Any) -> None:
    world.step(1)


def set_kinematic_targets(
    world: Any, bodies: list[int], transforms: np.ndarray, velocities: np.ndarray
) -> None:
    setter = getattr(world, "set_kinematic_targets", None)
    if setter is None:
        raise RuntimeError(
            "this abdsim.World has no kinematic-target API (set_kinematic_targets); "
            "use driver.targets(t) to get the target poses"
        )
    setter(bodies, transforms, velocities)
