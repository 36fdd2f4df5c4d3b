"""Scene: the geometries to simulate and the settings to simulate them with."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from abdsim.geometry.simplicial_complex import SimplicialComplex
from abdsim.sim.joints import (
    ActuatorHandle,
    JointHandle,
    body_index,
    check_tree,
    make_actuator,
    make_joint,
)
from abdsim.sim.sensors import SensorSet
from abdsim.sim.settings import SceneSettings

GROUND = "ground"  #: the ground's name in ``Scene.contact_table``


@dataclass(frozen=True)
class Ground:
    """The half-space z >= height, a fixed obstacle (``Scene.add_ground``)."""

    height: float = 0.0
    friction: float | None = None  #: μ against the ground (None: the scene's ``friction``)
    #: normal damping ratio ζ against the ground (None: the scene's ``contact_damping``)
    damping: float | None = None


class ContactTable:
    """Which contact elements collide, and with which friction coefficient.

    Every body carries a contact element id (``scene.add(sc, contact_element=k)``, default 0);
    the ground is ``"ground"``. By default every pair collides with the scene's ``friction``
    (and the ground's own friction, if ``add_ground`` gave one). Pairs of one element with
    itself are allowed (bodies of the same element). A pair's normal damping ratio ζ
    (``SceneSettings.contact_damping``) and coefficient of restitution e
    (``SceneSettings.restitution``) are set here too.
    """

    def __init__(self) -> None:
        self._rules: dict[tuple, tuple[bool, float | None]] = {}
        self._damping: dict[tuple, float] = {}
        self._restitution: dict[tuple, float] = {}

    @staticmethod
    def _key(a: int | str, b: int | str) -> tuple:
        for e in (a, b):
            if e != GROUND and not (isinstance(e, (int, np.integer)) and 0 <= int(e) < 65536):
                raise ValueError(
                    f"contact element must be an integer in [0, 65536) or {GROUND!r}, got {e!r}"
                )
        a = GROUND if a == GROUND else int(a)
        b = GROUND if b == GROUND else int(b)
        return tuple(sorted((a, b), key=lambda e: (e == GROUND, e if e != GROUND else 0)))

    def set(
        self,
        a: int | str,
        b: int | str,
        enabled: bool = True,
        friction: float | None = None,
        damping: float | None = None,
        restitution: float | None = None,
    ) -> None:
        """Whether elements a and b collide (``enabled``), with which μ, which normal
        damping ratio ζ and which coefficient of restitution e in [0, 1] (None: the scene's
        ``friction`` / ``contact_damping`` / ``restitution``)."""
        for name, v in (("friction", friction), ("damping", damping)):
            if v is not None and not (np.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be finite and >= 0, got {v!r}")
        if restitution is not None and not (np.isfinite(restitution) and 0 <= restitution <= 1):
            raise ValueError(f"restitution must be in [0, 1], got {restitution!r}")
        key = self._key(a, b)
        self._rules[key] = (
            bool(enabled),
            None if friction is None else float(friction),
        )
        if damping is None:
            self._damping.pop(key, None)
        else:
            self._damping[key] = float(damping)
        if restitution is None:
            self._restitution.pop(key, None)
        else:
            self._restitution[key] = float(restitution)

    def damping(self, a: int | str, b: int | str) -> float | None:
        """The pair's normal damping ratio ζ, or None for the scene's default."""
        return self._damping.get(self._key(a, b))

    def restitution(self, a: int | str, b: int | str) -> float | None:
        """The pair's coefficient of restitution e, or None for the scene's default."""
        return self._restitution.get(self._key(a, b))

    def get(self, a: int | str, b: int | str) -> tuple[bool, float | None]:
        """(enabled, friction or None for the default) of a pair."""
        return self._rules.get(self._key(a, b), (True, None))

    def items(self):
        return self._rules.items()

    def __len__(self) -> int:
        return len(self._rules)

    def __repr__(self) -> str:
        return f"<ContactTable {len(self._rules)} rule(s)>"


@dataclass(frozen=True)
class BodyHandle:
    """The bodies one ``Scene.add`` call created: every instance of one geometry.

    Bodies are numbered geometry by geometry, instance by instance: instance ``i`` of this
    geometry is body ``start + i``.
    """

    geometry: int  #: index in ``Scene.geometries``
    start: int  #: first body index
    stop: int  #: one past the last body index
    sc: SimplicialComplex = field(repr=False, compare=False)
    #: contact element id of each instance (``Scene.contact_table``)
    contact_elements: tuple[int, ...] = field(default=(), repr=False, compare=False)
    #: the bodies start kinematic (held at their pose until given targets)
    kinematic: bool = False

    @property
    def bodies(self) -> range:
        """Body indices of this geometry's instances."""
        return range(self.start, self.stop)

    def body(self, instance: int = 0) -> int:
        """Body index of one instance."""
        if not 0 <= instance < len(self):
            raise IndexError(f"instance {instance} out of range [0, {len(self)})")
        return self.start + instance

    def __len__(self) -> int:
        return self.stop - self.start


class Scene:
    """Geometries (each instance an affine body) plus the simulation settings.

    Args:
        dt: time step (s).
        gravity: gravitational acceleration (m/s²), z-up by default.
        integrator: ``"bdf1"`` or ``"bdf2"``.
        settings: a full ``SceneSettings`` to start from (copied).
        **kwargs: any other ``SceneSettings`` field (``newton_tol_translation=...``).

    Raises:
        ValueError: for a setting out of range; TypeError for an unknown setting or one of
            the wrong type (``dt=True``, ``contact="False"``).
    """

    def __init__(
        self,
        dt: float | None = None,
        gravity: tuple[float, float, float] | np.ndarray | None = None,
        integrator: str | None = None,
        *,
        settings: SceneSettings | None = None,
        **kwargs: Any,
    ) -> None:
        base = replace(settings) if settings is not None else SceneSettings()
        unknown = set(kwargs) - set(SceneSettings.field_names())
        if unknown:
            raise TypeError(
                f"unknown scene setting(s) {sorted(unknown)}; known: {SceneSettings.field_names()}"
            )
        given = {"dt": dt, "gravity": gravity, "integrator": integrator}
        kwargs.update({k: v for k, v in given.items() if v is not None})
        if "gravity" in kwargs:
            kwargs["gravity"] = tuple(float(x) for x in np.asarray(kwargs["gravity"]).reshape(-1))
        self.settings: SceneSettings = replace(base, **kwargs)
        self.settings.validate()
        self._geometries: list[SimplicialComplex] = []
        self._handles: list[BodyHandle] = []
        self._ground: Ground | None = None
        self.contact_table = ContactTable()
        self._joints: list[JointHandle] = []
        self._actuators: list[ActuatorHandle] = []
        #: sensors every World of this scene starts with (``sensors.add(...)``, MJCF sensors)
        self.sensors = SensorSet()

    @property
    def dt(self) -> float:
        return self.settings.dt

    @property
    def gravity(self) -> np.ndarray:
        return np.asarray(self.settings.gravity, dtype=np.float64)

    @property
    def geometries(self) -> list[SimplicialComplex]:
        """Added geometries, in order (a copy of the list; the geometries themselves)."""
        return list(self._geometries)

    @property
    def handles(self) -> list[BodyHandle]:
        """One handle per added geometry, in order."""
        return list(self._handles)

    @property
    def num_bodies(self) -> int:
        return self._handles[-1].stop if self._handles else 0

    @property
    def ground(self) -> Ground | None:
        """The ground (``add_ground``), or None."""
        return self._ground

    def add_ground(
        self, height: float = 0.0, friction: float | None = None, damping: float | None = None
    ) -> Ground:
        """Add the ground: the half-space z >= ``height`` (m), a fixed obstacle for contact.

        Args:
            height: ground height (m).
            friction: μ between the ground and every body (None: the scene's ``friction``);
                ``contact_table.set(k, "ground", ...)`` overrides it per element.
            damping: normal damping ratio ζ between the ground and every body (None: the
                scene's ``contact_damping``); per element as friction.

        Raises:
            ValueError: non-finite values, or a second ground at another height.
        """
        height = float(height)
        if not np.isfinite(height):
            raise ValueError(f"ground height must be finite, got {height!r}")
        if friction is not None:
            friction = float(friction)
            if not (np.isfinite(friction) and friction >= 0):
                raise ValueError(f"ground friction must be finite and >= 0, got {friction!r}")
        if damping is not None:
            damping = float(damping)
            if not (np.isfinite(damping) and damping >= 0):
                raise ValueError(f"ground damping must be finite and >= 0, got {damping!r}")
        if self._ground is not None and self._ground.height != height:
            raise ValueError(
                f"the scene already has a ground at z = {self._ground.height}; only one ground "
                "is supported (use a fixed body for other obstacles)"
            )
        if self._ground is not None and friction is None:
            friction = self._ground.friction
        if self._ground is not None and damping is None:
            damping = self._ground.damping
        self._ground = Ground(height, friction, damping)
        return self._ground

    def add(
        self, sc: SimplicialComplex, contact_element: int | Any = 0, kinematic: bool = False
    ) -> BodyHandle:
        """Add every instance of ``sc`` as a body; returns their handle.

        ``sc`` must carry a constitution (``AffineBodyConstitution(...).apply_to(sc, kappa)``).
        Its attributes are read when a ``World`` is built, so they can still be edited
        (velocities, flags, transforms), but not its instance count.

        Args:
            sc: the geometry (every instance becomes a body).
            contact_element: contact element id of the bodies (one int, or one per
                instance), for ``contact_table``.
            kinematic: the bodies are scripted from the start (e.g. robot links): the World
                holds them at their pose until ``set_kinematic_target``/``schedule`` moves
                them. Contact ignores pairs of two kinematic or fixed bodies (and kinematic
                bodies with the ground), so overlapping links are fine.

        Raises:
            ValueError: no constitution, no instances, ``sc`` already added, or bad
                contact elements.
        """
        if not isinstance(sc, SimplicialComplex):
            raise TypeError(f"Scene.add expects a SimplicialComplex, got {type(sc).__name__}")
        if "constitution_uid" not in sc.meta:
            raise ValueError(
                "geometry has no constitution: apply one first, e.g. "
                "abdsim.AffineBodyConstitution('OrthoPotential').apply_to(sc, kappa=1e8)"
            )
        if any(g is sc for g in self._geometries):
            raise ValueError("this SimplicialComplex was already added to the scene")
        if sc.instance_count < 1:
            raise ValueError("geometry has no instances")
        try:
            elements = np.broadcast_to(np.asarray(contact_element), (sc.instance_count,))
        except ValueError:
            raise ValueError(
                f"contact_element: one id or {sc.instance_count} (one per instance), got "
                f"{contact_element!r}"
            ) from None
        if not np.issubdtype(elements.dtype, np.integer) or (
            elements.size and (elements.min() < 0 or elements.max() >= 65536)
        ):
            raise ValueError(
                "contact_element must be an integer in [0, 65536) (or one per instance), got "
                f"{contact_element!r}"
            )
        start = self.num_bodies
        handle = BodyHandle(
            len(self._geometries),
            start,
            start + sc.instance_count,
            sc,
            tuple(int(e) for e in elements),
            bool(kinematic),
        )
        self._geometries.append(sc)
        self._handles.append(handle)
        return handle

    @property
    def joints(self) -> list[JointHandle]:
        """Added joints, in order (the order of the joint coordinates)."""
        return list(self._joints)

    def add_joint(
        self,
        kind: str,
        parent: BodyHandle | int | None = None,
        child: BodyHandle | int | None = None,
        anchor: Any = (0.0, 0.0, 0.0),
        axis: Any = (0.0, 0.0, 1.0),
        limits: tuple[float, float] | None = None,
        damping: float = 0.0,
        armature: float = 0.0,
        stiffness: float = 0.0,
        ref: float = 0.0,
        frictionloss: float = 0.0,
        name: str | None = None,
        collide: bool = False,
    ) -> JointHandle:
        """Join ``child`` to ``parent`` (None: the world); the World holds it exactly.

        Args:
            kind: ``"revolute"`` (also ``"hinge"``, ``"continuous"``), ``"prismatic"``
                (``"slide"``), ``"ball"`` (``"spherical"``), ``"fixed"`` (``"weld"``) or
                ``"free"`` (no constraint; world parent only).
            parent, child: a handle of a one-instance geometry or a body index.
            anchor: the joint's world position in the configuration the World is built from.
            axis: hinge or slide direction in the world at that configuration.
            limits: (lower, upper) in the joint coordinate (relative to load, so lower < 0 <
                upper): a barrier that is never crossed (the joint stops within 1e-3 of it).
            damping, armature, stiffness, ref, frictionloss: MuJoCo's joint damping (viscous,
                implicit), armature (added inertia), spring stiffness about ``ref`` and dry
                friction loss (smoothed below 1e-3 rad/s or m/s). Joint physics act on
                revolute and prismatic joints only.
            name: the joint's name (default ``joint<i>``).
            collide: whether contact acts between parent and child. Off by default (as in
                MuJoCo): joined bodies touch at the joint, and link meshes often overlap
                there; contact with every other body and the ground is kept.

        Raises:
            ValueError naming the joint: unknown kind, zero axis, parent == child, a body
                with two parents or a loop, negative damping/armature/stiffness/
                frictionloss, limits with lower > upper. An anchor far from both bodies is
                reported when the World is built.
        """
        index = len(self._joints)
        who = f"joint '{name if name is not None else f'joint{index}'}'"
        n = self.num_bodies
        joint = make_joint(
            index,
            kind,
            body_index(f"{who} parent", parent, n, allow_world=True),
            body_index(f"{who} child", child, n, allow_world=False),
            anchor,
            axis,
            limits,
            damping,
            armature,
            stiffness,
            ref,
            frictionloss,
            name,
            collide,
        )
        check_tree(self._joints, joint)
        self._joints.append(joint)
        return joint

    @property
    def actuators(self) -> list[ActuatorHandle]:
        """Added actuators, in order (the order of ``world.ctrl``)."""
        return list(self._actuators)

    def add_actuator(
        self,
        joint: JointHandle | int | str,
        kind: str = "motor",
        kp: float = 0.0,
        kv: float = 0.0,
        gear: float = 1.0,
        ctrl_range: tuple[float, float] | None = None,
        force_range: tuple[float, float] | None = None,
        bias: float = 0.0,
    ) -> ActuatorHandle:
        """Drive a revolute or prismatic joint like MuJoCo's motor / position / velocity
        actuator (see ``ActuatorHandle``); its control is ``world.ctrl[handle.index]``;
        ``bias`` is a constant force added before the force range (MuJoCo's ``biasprm[0]``).

        Raises:
            ValueError naming the actuator and joint: unknown kind or joint, a joint that is
                not 1-dof, negative gains, zero gear, a non-finite bias, a range with lower > upper.
        """
        if isinstance(joint, JointHandle):
            if joint.index >= len(self._joints) or self._joints[joint.index] is not joint:
                raise ValueError(f"joint '{joint.name}' is not a joint of this scene")
        elif isinstance(joint, str):
            found = [j for j in self._joints if j.name == joint]
            if not found:
                raise ValueError(f"no joint named {joint!r}")
            joint = found[0]
        elif isinstance(joint, (int, np.integer)) and 0 <= int(joint) < len(self._joints):
            joint = self._joints[int(joint)]
        else:
            raise ValueError(f"unknown joint {joint!r}")
        handle = make_actuator(
            len(self._actuators), joint, kind, kp, kv, gear, ctrl_range, force_range, bias
        )
        self._actuators.append(handle)
        return handle

    def contact_exclusions(self) -> list[tuple[int, int]]:
        """Pairs of bodies (smaller index first) that never collide: those joined by a joint
        with ``collide=False``."""
        pairs = {
            (min(j.parent, j.child), max(j.parent, j.child))
            for j in self._joints
            if not j.collide and j.parent >= 0
        }
        return sorted(pairs)

    def contact_elements(self) -> np.ndarray:
        """Contact element id of every body, (n_bodies,) int32."""
        return np.array([e for h in self._handles for e in h.contact_elements], dtype=np.int32)

    def __repr__(self) -> str:
        return (
            f"<Scene geometries={len(self._geometries)} bodies={self.num_bodies} "
            f"dt={self.dt} integrator={self.settings.integrator}>"
        )
