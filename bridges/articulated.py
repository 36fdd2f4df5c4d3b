"""Loaded scenes as articulations: the bodies a source moves on revolute, prismatic or ball
joints become dynamic affine bodies joined by abdsim's exact joints (``Scene.add_joint``), with
the source's joint damping, armature, spring, friction loss and limits (MJCF; URDF
``<dynamics damping friction>`` and ``<limit lower upper>``), and the MJCF actuators on
``world.ctrl`` (``bridges/_mjcf_actuators.py``).

This is what ``load_urdf`` / ``load_mjcf`` build by default (``kinematic=False``):
``result.scene`` and ``result.make_world()`` call :func:`build_articulated_scene`. Joint
coordinates are relative to the loaded configuration; ``bridges/_joint_map.py`` maps them to
and from MuJoCo's ``qpos``/``qvel`` and Pinocchio's ``q``/``v``.

Free joints are not scene joints (a free body needs no constraint): the mappings read them
from the bodies' states.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from typing import Any

import numpy as np

from abdsim.bridges._bodies import JointInfo, LoaderError, LoadResult
from abdsim.bridges._world_adapter import build_scene

_KINDS = ("revolute", "prismatic", "ball")
#: A limit closer than this to the loaded coordinate is moved out to it: the joint-limit
#: barrier (reach 1e-3) needs the start strictly inside the limits.
_LIMIT_CLEARANCE = 2e-3


def _limits(
    result: LoadResult, joint: JointInfo, lo: float, hi: float, q0: float
) -> tuple[float, float] | None:
    """Source limits (absolute) as abdsim limits (relative to the loaded q0), with a note
    where the loaded configuration sits on or beyond one of them."""
    lo, hi = lo - q0, hi - q0
    moved = []
    if lo > -_LIMIT_CLEARANCE:
        moved.append(f"lower {lo + q0:g} -> {q0 - _LIMIT_CLEARANCE:g}")
        lo = -_LIMIT_CLEARANCE
    if hi < _LIMIT_CLEARANCE:
        moved.append(f"upper {hi + q0:g} -> {q0 + _LIMIT_CLEARANCE:g}")
        hi = _LIMIT_CLEARANCE
    if moved:
        _note(
            result,
            f"joint {joint.name!r}: the loaded position {q0:g} is on or beyond its limit(s); "
            f"moved {', '.join(moved)} so that it starts inside them",
        )
    return (lo, hi)


def _note(result: LoadResult, note: str) -> None:
    """A note found while building the scene: kept in ``result.notes`` and warned, once."""
    if note not in result.notes:
        result.notes.append(note)
        warnings.warn(note, stacklevel=4)


def _mjcf_physics(result: LoadResult, joint: JointInfo) -> dict[str, Any]:
    """MuJoCo's damping, armature, frictionloss, stiffness/springref and range of a joint,
    in abdsim's coordinates (relative to the loaded qpos)."""
    m = result.model
    if joint.type == "ball":
        return {}
    j = joint.source_id if joint.source_id is not None else m.joint(joint.name).id
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
        physics["limits"] = _limits(result, joint, *(float(x) for x in m.jnt_range[j]), q0)
    return physics


def _urdf_physics(result: LoadResult, joint: JointInfo) -> dict[str, Any]:
    """URDF ``<dynamics damping friction>`` (Pinocchio's ``model.damping``/``friction``) and
    ``<limit lower upper>`` of a revolute or prismatic joint; continuous joints (Pinocchio's
    unbounded ``RUB`` joints) and a limit with lower >= upper (URDF writers' ``0 0``) have no
    limits."""
    m = result.model
    if joint.type == "ball":
        return {}
    j = joint.source_id if joint.source_id is not None else int(m.getJointId(joint.name))
    iq, iv = int(m.idx_qs[j]), int(m.idx_vs[j])
    physics: dict[str, Any] = {
        "damping": float(m.damping[iv]),
        "frictionloss": float(m.friction[iv]),
    }
    if int(m.nqs[j]) == 1:
        lo, hi = float(m.lowerPositionLimit[iq]), float(m.upperPositionLimit[iq])
        if lo < hi and np.isfinite(lo) and np.isfinite(hi):
            q0 = float(result.q[iq]) if result.q is not None else 0.0
            physics["limits"] = _limits(result, joint, lo, hi, q0)
        elif np.isfinite(lo) and lo == hi:
            _note(
                result,
                f"joint {joint.name!r}: <limit lower={lo:g} upper={hi:g}> is empty: the joint "
                "is left without position limits (as an unlimited revolute)",
            )
    return physics


def check_articulation(result: LoadResult) -> None:
    """LoaderError naming the file, body and joints for what abdsim cannot articulate: a joint
    kind it has no model of, a body moved by several joints (the MJCF loader splits those into
    chains of joint frames, ``bridges/_joint_frames.py``; a hand-made LoadResult may not)."""
    where = f"{result.format.upper()} {result.source.name}"
    per_child: dict[int, list[JointInfo]] = {}
    for j in result.joints:
        if j.type not in _KINDS and j.type != "free":
            source = ""
            if result.format == "urdf" and j.source_id is not None and result.model is not None:
                source = f" (Pinocchio {result.model.joints[j.source_id].shortname()})"
            raise LoaderError(
                f"{where}: joint {j.name!r} (body {result.bodies[j.child].name!r}): type "
                f"{j.type!r}{source} is not supported as a dynamic joint (revolute, "
                "continuous, prismatic, spherical and a floating root are); load with "
                "kinematic=True to script it"
            )
        per_child.setdefault(j.child, []).append(j)
    for child, joints in per_child.items():
        if len(joints) > 1:
            raise LoaderError(
                f"{where}: body {result.bodies[child].name!r} moves on {len(joints)} joints "
                f"({', '.join(f'{j.name!r} {j.type}' for j in joints)}): abdsim joins two "
                "bodies by one joint; give each joint its own child body (load_mjcf does so "
                "with joint frames) or load with kinematic=True to script it"
            )


def build_articulated_scene(result: LoadResult, **settings: Any):
    """A Scene of `result` (as ``build_scene``) whose jointed bodies are dynamic and joined,
    with the source's joint physics and (MJCF) actuators.

    Raises:
        LoaderError: a joint type abdsim does not model, a body on several joints (not
            split into joint frames), joint data abdsim rejects (the message names the joint).
    """
    check_articulation(result)
    bodies = [replace(b, kind="dynamic") if b.kind == "kinematic" else b for b in result.bodies]
    scene = build_scene(replace(result, bodies=bodies, _scene=None), **settings)
    physics_of = _mjcf_physics if result.format == "mjcf" else _urdf_physics
    for j in result.joints:
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
                **(physics_of(result, j) if result.model is not None else {}),
            )
        except ValueError as e:
            raise LoaderError(f"{result.format.upper()} {result.source.name}: {e}") from None
    if result.format == "mjcf" and result.actuators:
        from abdsim.bridges._mjcf_actuators import add_actuators

        add_actuators(scene, result)
    return scene
