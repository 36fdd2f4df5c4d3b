"""Joints between affine bodies: their description (``Scene.add_joint``) and checks.

A joint ties a child body to a parent body (or to the world) at a world ``anchor`` given in
the configuration the scene is loaded in; the World enforces it exactly inside every Newton
solve (ABD_NOTES §8). Joint coordinates follow MuJoCo: hinge angle and slide displacement
relative to the loaded configuration, a ball as a w-first unit quaternion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

#: Accepted kind names (URDF and MJCF spellings) -> the kind.
JOINT_KINDS: dict[str, str] = {
    "revolute": "revolute",
    "continuous": "revolute",
    "hinge": "revolute",
    "prismatic": "prismatic",
    "slide": "prismatic",
    "ball": "ball",
    "spherical": "ball",
    "fixed": "fixed",
    "weld": "fixed",
    "free": "free",
}

#: (nq, nv) per kind.
JOINT_DOFS: dict[str, tuple[int, int]] = {
    "revolute": (1, 1),
    "prismatic": (1, 1),
    "ball": (4, 3),
    "free": (7, 6),
    "fixed": (0, 0),
}


@dataclass(frozen=True)
class JointHandle:
    """One joint of a scene (``Scene.add_joint``)."""

    index: int  #: position in ``Scene.joints`` (joint order of the coordinates)
    name: str
    kind: str  #: "revolute", "prismatic", "ball", "fixed" or "free"
    parent: int  #: parent body index, -1 for the world
    child: int  #: child body index
    anchor: tuple[float, float, float]  #: world anchor at load (m)
    axis: tuple[float, float, float]  #: unit world axis at load (revolute, prismatic)
    limits: tuple[float, float] | None = None
    damping: float = 0.0
    armature: float = 0.0
    stiffness: float = 0.0
    ref: float = 0.0
    frictionloss: float = 0.0
    #: whether contact acts between parent and child (False: they may touch or overlap at the
    #: joint, as MuJoCo excludes parent-child contact)
    collide: bool = False

    @property
    def nq(self) -> int:
        """Number of position coordinates."""
        return JOINT_DOFS[self.kind][0]

    @property
    def nv(self) -> int:
        """Number of velocity coordinates."""
        return JOINT_DOFS[self.kind][1]

    def core_physics(self):
        """The C++ ``JointPhysics`` of this joint."""
        from abdsim._native import _core

        p = _core.JointPhysics()
        p.stiffness, p.ref, p.damping = self.stiffness, self.ref, self.damping
        p.armature, p.frictionloss = self.armature, self.frictionloss
        if self.limits is not None:
            p.limited, p.lower, p.upper = True, self.limits[0], self.limits[1]
        return p

    def physics(self) -> dict[str, Any]:
        """The joint's physics settings that differ from a plain ideal joint."""
        out: dict[str, Any] = {}
        if self.limits is not None:
            out["limits"] = self.limits
        for key in ("damping", "armature", "stiffness", "frictionloss"):
            if getattr(self, key) != 0.0:
                out[key] = getattr(self, key)
        return out


ACTUATOR_KINDS = ("motor", "position", "velocity")


@dataclass(frozen=True)
class ActuatorHandle:
    """One actuator of a scene (``Scene.add_actuator``); its control is ``world.ctrl[index]``.

    MuJoCo's ``general`` actuator with the motor / position / velocity presets, acting on a
    1-dof joint: force = gain·u + bias + b1·gear·θ + b2·gear·θ̇ (motor: 1, 0, 0; position: kp,
    −kp, −kv; velocity: kv, 0, −kv), clamped to ``force_range``; the joint gets gear·force. The
    control u is clamped to ``ctrl_range``. ``bias`` is a constant force (MuJoCo's ``biasprm[0]``);
    a position actuator whose target is measured from somewhere other than the joint's loaded
    position (θ = 0) takes ``bias = −kp·gear·θ_offset``.
    """

    index: int
    joint: int  #: joint index
    kind: str
    kp: float = 0.0
    kv: float = 0.0
    gear: float = 1.0
    ctrl_range: tuple[float, float] | None = None
    force_range: tuple[float, float] | None = None
    bias: float = 0.0


def _finite(who: str, what: str, value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{who}: {what} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{who}: {what} must be finite, got {value!r}")
    return v


def _range(who: str, what: str, value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    try:
        lo, hi = (float(x) for x in value)
    except (TypeError, ValueError):
        raise ValueError(f"{who}: {what} must be (lower, upper), got {value!r}") from None
    if math.isnan(lo) or math.isnan(hi) or lo > hi:
        raise ValueError(f"{who}: {what} must have lower <= upper, got ({lo}, {hi})")
    return (lo, hi)


def make_actuator(
    index: int,
    joint: JointHandle,
    kind: str,
    kp: float,
    kv: float,
    gear: float,
    ctrl_range: Any,
    force_range: Any,
    bias: float = 0.0,
) -> ActuatorHandle:
    """Checks one actuator (ValueError naming it and its joint) and returns its handle."""
    who = f"actuator {index} on joint '{joint.name}'"
    if kind not in ACTUATOR_KINDS:
        raise ValueError(f"{who}: unknown actuator kind {kind!r}; known: {ACTUATOR_KINDS}")
    if joint.kind not in ("revolute", "prismatic"):
        raise ValueError(f"{who}: actuators drive revolute and prismatic joints only")
    gear = float(gear)
    if not (math.isfinite(gear) and gear != 0.0):
        raise ValueError(f"{who}: gear must be finite and non-zero, got {gear!r}")
    return ActuatorHandle(
        index=index,
        joint=joint.index,
        kind=kind,
        kp=_non_negative(who, "kp", kp),
        kv=_non_negative(who, "kv", kv),
        gear=gear,
        ctrl_range=_range(who, "ctrl_range", ctrl_range),
        force_range=_range(who, "force_range", force_range),
        bias=_finite(who, "bias", bias),
    )


def body_index(who: str, value: Any, n_bodies: int, allow_world: bool) -> int:
    """A body index from a one-instance BodyHandle, an int, or None (the world)."""
    from abdsim.sim.scene import BodyHandle

    if value is None:
        if not allow_world:
            raise ValueError(f"{who}: the child must be a body, not the world (None)")
        return -1
    if isinstance(value, BodyHandle):
        if len(value) != 1:
            raise ValueError(
                f"{who}: a handle of {len(value)} instances is ambiguous; pass "
                "handle.body(i) for one of them"
            )
        return value.start
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        if not 0 <= int(value) < n_bodies:
            raise ValueError(f"{who}: body index {value} out of range [0, {n_bodies})")
        return int(value)
    raise ValueError(f"{who}: expected a BodyHandle, a body index or None, got {value!r}")


def _vector(who: str, what: str, value: Any) -> tuple[float, float, float]:
    try:
        v = np.asarray(value, dtype=np.float64).reshape(3)
    except (TypeError, ValueError):
        raise ValueError(f"{who}: {what} must be 3 numbers, got {value!r}") from None
    if not np.isfinite(v).all():
        raise ValueError(f"{who}: {what} must be finite, got {value!r}")
    return (float(v[0]), float(v[1]), float(v[2]))


def _non_negative(who: str, what: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value >= 0.0):
        raise ValueError(f"{who}: {what} must be finite and >= 0, got {value!r}")
    return value


def make_joint(
    index: int,
    kind: str,
    parent: int,
    child: int,
    anchor: Any,
    axis: Any,
    limits: Any,
    damping: float,
    armature: float,
    stiffness: float,
    ref: float,
    frictionloss: float,
    name: str | None,
    collide: bool = False,
) -> JointHandle:
    """Checks one joint's own data (ValueError naming it) and returns its handle."""
    name = f"joint{index}" if name is None else str(name)
    who = f"joint '{name}'"
    if not isinstance(kind, str) or kind.lower() not in JOINT_KINDS:
        raise ValueError(f"{who}: unknown joint kind {kind!r}; known: {sorted(JOINT_KINDS)}")
    kind = JOINT_KINDS[kind.lower()]
    if parent == child:
        raise ValueError(f"{who}: parent and child are the same body ({child})")
    if kind == "free" and parent != -1:
        raise ValueError(f"{who}: a free joint must have the world (None) as parent")
    anchor_v = _vector(who, "anchor", anchor)
    axis_v = _vector(who, "axis", axis)
    norm = math.sqrt(sum(a * a for a in axis_v))
    if kind in ("revolute", "prismatic"):
        if norm < 1e-12:
            raise ValueError(f"{who}: the axis is zero")
        axis_v = tuple(a / norm for a in axis_v)
    if limits is not None and kind not in ("revolute", "prismatic"):
        raise ValueError(f"{who}: limits apply to revolute and prismatic joints only")
    limits_v = _range(who, "limits", limits)
    ref = float(ref)
    if not math.isfinite(ref):
        raise ValueError(f"{who}: ref must be finite, got {ref!r}")
    if not isinstance(collide, (bool, np.bool_)):
        raise ValueError(f"{who}: collide must be True or False, got {collide!r}")
    return JointHandle(
        index=index,
        name=name,
        kind=kind,
        parent=parent,
        child=child,
        anchor=anchor_v,
        axis=axis_v,
        limits=limits_v,
        damping=_non_negative(who, "damping", damping),
        armature=_non_negative(who, "armature", armature),
        stiffness=_non_negative(who, "stiffness", stiffness),
        ref=ref,
        frictionloss=_non_negative(who, "frictionloss", frictionloss),
        collide=bool(collide),
    )


def check_tree(joints: list[JointHandle], new: JointHandle) -> None:
    """ValueError when ``new`` gives a body a second parent or closes a loop."""
    who = f"joint '{new.name}'"
    if any(j.name == new.name for j in joints):
        raise ValueError(f"{who}: a joint with this name already exists")
    if any(j.child == new.child for j in joints):
        raise ValueError(
            f"{who}: body {new.child} is already the child of another joint (each body has one "
            "parent joint; loops are not supported)"
        )
    parent_of = {j.child: j.parent for j in joints}
    b = new.parent
    while b != -1:
        if b == new.child:
            raise ValueError(f"{who}: it closes a kinematic loop (loops are not supported)")
        b = parent_of.get(b, -1)
