"""The one place where bridges touch ``abdsim.Scene`` / ``abdsim.World``.

Loaders, drivers and the logger call these functions instead of the World's methods, so a
change of the World's API is absorbed here. What is used:

* ``abdsim.Scene(dt=..., gravity=..., **settings)``, ``scene.add(sc) -> handle`` (body
  ``handle.start``), ``scene.geometries``, ``scene.settings``; ``scene.add_ground(height)``
  when the Scene has it.
* ``abdsim.World(scene)``, ``world.step(1)``, ``world.time``, ``world.step_count``,
  ``world.scene``, ``world.transforms()``, ``world.velocities()``, ``world.diagnostics``,
  ``world.set_kinematic_targets(bodies, transforms)`` (target at the end of the next step),
  ``world.set_kinematic_schedule(body, t -> T)``.
"""

from __future__ import annotations

import inspect
import weakref
from dataclasses import dataclass
from typing import Any

import numpy as np

#: Scenes built from a LoadResult -> that result (body names and kinds for logging).
_SOURCES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass
class BodyDescription:
    """Name, kind and surface (body frame) of one body, for logging."""

    name: str
    kind: str
    vertices: np.ndarray
    triangles: np.ndarray


def _abdsim_class(name: str) -> Any:
    import abdsim

    cls = getattr(abdsim, name, None)
    if cls is None:
        raise RuntimeError(
            f"abdsim.{name} is not available in this version of abdsim: use "
            "result.geometries (one SimplicialComplex per body) and result.dt / gravity / "
            "grounds to set up a simulation by hand"
        )
    return cls


def _scene_settings_fields(scene_cls: Any) -> set[str]:
    settings = getattr(__import__("abdsim"), "SceneSettings", None)
    if settings is not None and hasattr(settings, "field_names"):
        return set(settings.field_names())
    return {"dt", "gravity"}


def build_scene(result: Any, **settings: Any) -> Any:
    """A Scene with every body of a LoadResult (body i = ``result.bodies[i]``).

    The source's settings (``dt``, ``gravity``; a ground plane, friction and contact damping
    where the Scene supports them) are used unless ``settings`` overrides them.
    """
    scene_cls = _abdsim_class("Scene")
    known = _scene_settings_fields(scene_cls)
    kwargs: dict[str, Any] = {}
    if result.dt is not None:
        kwargs["dt"] = float(result.dt)
    if result.gravity is not None:
        kwargs["gravity"] = tuple(float(g) for g in result.gravity)
    frictions = [g.friction for g in result.grounds if g.friction is not None]
    frictions += [b.friction for b in result.bodies if b.friction is not None]
    if frictions and "friction" in known:
        kwargs["friction"] = float(max(frictions))  # MuJoCo combines a pair by the max
    damping = getattr(result, "contact_damping", None)
    if damping is not None and "contact_damping" in known:
        kwargs["contact_damping"] = float(damping)
    kwargs.update(settings)
    scene = scene_cls(**kwargs)
    # Kinematic links declared as such up front, where the Scene supports it: contact then
    # ignores link-link overlaps (which joints make common) from the initial check on.
    add_kinematic = "kinematic" in inspect.signature(scene.add).parameters
    rules = getattr(result, "contact_rules", None)
    for i, body in enumerate(result.bodies):
        # With contact rules every body is its own contact element (bridges/_contact_rules.py).
        extra = {"contact_element": i} if rules is not None else {}
        if add_kinematic:
            handle = scene.add(body.geometry, kinematic=body.kind == "kinematic", **extra)
        else:
            handle = scene.add(body.geometry, **extra)
        start = getattr(handle, "start", i)
        if start != i:  # pragma: no cover - a fresh scene numbers bodies from 0
            raise RuntimeError(f"body {body.name!r} got index {start}, expected {i}")
    add_ground = getattr(scene, "add_ground", None)
    for ground in result.grounds:
        if add_ground is None:
            break
        if not np.allclose(ground.normal, [0.0, 0.0, 1.0], atol=1e-12):
            raise ValueError(
                f"ground {ground.name!r} is tilted (normal {ground.normal.tolist()}): only a "
                "z-up ground is supported"
            )
        add_ground(float(ground.height))
    if rules is not None:
        rules.apply(scene, len(result.bodies))
    if getattr(result, "sensors", None) and hasattr(scene, "sensors"):
        scene.sensors.extend(result.sensors)
    _SOURCES[scene] = result
    return scene


def make_world(result: Any, scene: Any) -> Any:
    """A World of ``scene`` whose kinematic bodies rest at their loaded poses until driven."""
    world = _abdsim_class("World")(scene)
    kinematic = result.indices("kinematic")
    if kinematic:
        T = result.transforms()[kinematic]
        set_kinematic_targets(world, kinematic, T, np.zeros_like(T))
    return world


# -- descriptions -----------------------------------------------------------------------------
def _instance_kind(sc: Any, k: int) -> str:
    inst = sc.instances
    if "is_fixed" in inst and int(inst["is_fixed"][k]):
        return "fixed"
    return "dynamic"


def _describe_geometries(geometries: list[Any]) -> list[BodyDescription]:
    out = []
    for sc in geometries:
        for k in range(sc.instance_count):
            name = f"body{len(out)}"
            out.append(BodyDescription(name, _instance_kind(sc, k), sc.positions, sc.triangles))
    return out


def describe_bodies(source: Any) -> list[BodyDescription]:
    """Bodies of a LoadResult, a Scene, a World, or a list of SimplicialComplexes."""
    from abdsim.bridges._bodies import LoadResult

    if isinstance(source, LoadResult):
        return [
            BodyDescription(b.name, b.kind, b.geometry.positions, b.geometry.triangles)
            for b in source.bodies
        ]
    if isinstance(source, (list, tuple)):
        return _describe_geometries(list(source))
    scene = getattr(source, "scene", source)
    geometries = getattr(scene, "geometries", None)
    if geometries is None:
        raise TypeError(
            f"cannot find the bodies of a {type(source).__name__}: pass a World, a Scene, a "
            "LoadResult or a list of SimplicialComplexes"
        )
    out = _describe_geometries(list(geometries() if callable(geometries) else geometries))
    result = _SOURCES.get(scene) if _is_weakrefable(scene) else None
    if result is not None:
        for d, body in zip(out, result.bodies, strict=False):
            d.name, d.kind = body.name, body.kind
    return out


def _is_weakrefable(obj: Any) -> bool:
    try:
        weakref.ref(obj)
    except TypeError:
        return False
    return True


# -- world state ------------------------------------------------------------------------------
def _value(obj: Any, name: str) -> Any:
    v = getattr(obj, name)
    return v() if callable(v) else v


def world_time(world: Any) -> float:
    return float(_value(world, "time"))


def world_dt(world: Any) -> float:
    scene = getattr(world, "scene", None)
    if scene is not None and getattr(scene, "dt", None) is not None:
        return float(_value(scene, "dt"))
    return float(_value(world, "dt"))


def world_step_count(world: Any) -> int | None:
    return int(_value(world, "step_count")) if hasattr(world, "step_count") else None


def world_transforms(world: Any) -> np.ndarray:
    return np.asarray(world.transforms(), dtype=np.float64)


def world_velocities(world: Any) -> np.ndarray:
    if not hasattr(world, "velocities"):
        return np.zeros_like(world_transforms(world))
    return np.asarray(_value(world, "velocities"), dtype=np.float64)


def world_diagnostics(world: Any) -> Any:
    return _value(world, "diagnostics") if hasattr(world, "diagnostics") else None


def world_step(world: Any) -> None:
    world.step(1)


def set_kinematic_targets(
    world: Any, bodies: list[int], transforms: np.ndarray, velocities: np.ndarray
) -> None:
    """Targets at the end of the next step (the World derives velocities from the motion)."""
    setter = getattr(world, "set_kinematic_targets", None)
    if setter is None:
        raise RuntimeError(
            "this abdsim.World has no kinematic-target API (set_kinematic_targets); "
            "use driver.targets(t) to get the target poses"
        )
    setter(np.asarray(bodies, dtype=np.int64), np.asarray(transforms, dtype=np.float64))


def set_kinematic_schedule(world: Any, body: int, schedule: Any) -> None:
    setter = getattr(world, "set_kinematic_schedule", None)
    if setter is None:
        raise RuntimeError("this abdsim.World has no set_kinematic_schedule")
    setter(int(body), schedule)
