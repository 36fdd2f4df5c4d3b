"""Loaded scenes as articulations: the bodies a source moves on revolute, prismatic or ball
joints become dynamic affine bodies joined by abdsim's exact joints (``Scene.add_joint``), with
the source's joint damping, armature, spring, friction loss and limits (MJCF). Joint
coordinates are then relative to the loaded configuration: MuJoCo's qpos of a hinge or slide
is ``result.q[jnt_qposadr] + world.joint_positions()[k]``.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from abdsim.bridges._bodies import LoaderError, LoadResult
from abdsim.bridges._world_adapter import build_scene

_KINDS = ("revolute", "prismatic", "ball")


def _mjcf_physics(result: LoadResult, name: str, kind: str) -> dict[str, Any]:
    """MuJoCo's damping, armature, frictionloss, stiffness/springref and range of a joint,
    in abdsim's coordinates (relative to the loaded qpos)."""
    m = result.model
    if result.format != "mjcf" or m is None or kind == "ball":
        return {}
    j = m.joint(name).id
    dof, adr = int(m.jnt_dofadr[j]), int(m.jnt_qposadr[j])
    q0 = float(result.q[adr]) if result.q is not None else 0.0
    physics: dict[str, Any] = {
        "damping": float(m.dof_damping[dof]),
        "armature": float(m.dof_armature[dof]),
        "frictionloss": float(m.dof_frictionloss[dof]),
        "stiffness": float(m.jnt_stiffness[j]),
        "ref": float(m.qpos_spring[adr]) - q0,
    }
    if int(m.jnt_limited[j]):
        lo, hi = (float(x) - q0 for x in m.jnt_range[j])
        physics["limits"] = (lo, hi)
    return physics


def build_articulated_scene(result: LoadResult, **settings: Any):
    """A Scene of `result` (as ``build_scene``) whose jointed bodies are dynamic and joined.

    Raises:
        LoaderError: a joint type abdsim does not model (``other``), or a body on several
            joints (MJCF bodies with two hinges).
    """
    bodies = [replace(b, kind="dynamic") if b.kind == "kinematic" else b for b in result.bodies]
    joints = result.joints
    for j in joints:
        if j.type not in _KINDS and j.type != "free":
            raise LoaderError(f"joint {j.name!r}: type {j.type!r} is not supported")
    scene = build_scene(replace(result, bodies=bodies, _scene=None), **settings)
    for j in joints:
        if j.type == "free":
            continue
        axis = j.axis if j.axis is not None else np.array([0.0, 0.0, 1.0])
        try:
            scene.add_joint(
                j.type,
                parent=j.parent,
                child=j.child,
                anchor=j.anchor,
                axis=axis,
                name=j.name,
                **_mjcf_physics(result, j.name, j.type),
            )
        except ValueError as e:
            raise LoaderError(str(e)) from None
    return scene
