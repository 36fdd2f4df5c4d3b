"""Sensors in MuJoCo's layout: what each measures, where it sits, and where its values go.

A sensor is a frame fixed to a body (a MuJoCo *site*: position and orientation in the body's
rest frame, where x = A x̄ + p) that reads one quantity each step into ``World.sensordata``,
``sensor_dim[i]`` values from ``sensor_adr[i]``, as MuJoCo's ``mjData.sensordata``:

===============  ===  ========================================================================
type             dim  value (site frame unless said otherwise)
===============  ===  ========================================================================
touch            1    sum of the normal forces of the body's contacts whose point lies in the
                      site's zone (``zone``: sphere, box, capsule, cylinder, ellipsoid)
force            3    force on the body from its parent (the joint / script): m (a − g) −
                      contact force, over the last step; 0 for a free body
torque           3    the same interaction's torque about the site
accelerometer    3    linear acceleration of the site minus gravity over the last step
gyro             3    angular velocity
velocimeter      3    linear velocity of the site
framepos         3    position of the frame (world, or in the ``ref`` frame)
framequat        4    orientation quaternion [w, x, y, z] (world, or relative to ``ref``)
jointpos         1    a hinge's angle or a slide's displacement, MuJoCo's qpos (``offset``, the
                      loaded qpos, plus ``World.joint_positions()``)
jointvel         1    the joint's rate (``World.joint_velocities()``)
actuatorfrc      1    the force of actuator ``actuator`` (``Scene.add_actuator``) at the state:
                      gain·u + b1·gear·θ + b2·gear·θ̇, clamped, as MuJoCo's actuator_force
===============  ===  ========================================================================

Orientations are those of the rotation nearest to each body's A (polar decomposition).
Accelerations (accelerometer, force, torque) are the velocity change the last step applied:
(q̇_{t+1} − q̇_t)/h for BDF1, (3 q̇_{t+1} − 4 q̇_t + q̇_{t−1})/(2h) for BDF2, the
accelerations its momentum balance holds for; before the first step (and after
``set_state``) they read 0.
Joint sensors (jointpos, jointvel, actuatorfrc) sit on a joint or an actuator, not a body
(``SensorSet.add_joint_sensor``); one whose joint or actuator the World does not have (a
scene loaded without ``build_articulated_scene``) reads NaN. A sensor of a type abdsim cannot
compute keeps its slot, filled with NaN, so that indices stay MuJoCo's.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

#: Value dimension of each supported sensor type.
SENSOR_DIMS: dict[str, int] = {
    "touch": 1,
    "force": 3,
    "torque": 3,
    "accelerometer": 3,
    "gyro": 3,
    "velocimeter": 3,
    "framepos": 3,
    "framequat": 4,
    "jointpos": 1,
    "jointvel": 1,
    "actuatorfrc": 1,
}
#: Types read from joints and actuators rather than a body's frame.
JOINT_TYPES = frozenset({"jointpos", "jointvel", "actuatorfrc"})
#: Zone shapes of touch sensors (MuJoCo site types) and how many size values they use.
ZONE_SIZES: dict[str, int] = {"sphere": 1, "capsule": 2, "cylinder": 2, "ellipsoid": 3, "box": 3}
#: Types that need the last step's accelerations.
ACCELERATION_TYPES = frozenset({"accelerometer", "force", "torque"})


def quat_wxyz_to_rotation(quat: np.ndarray) -> np.ndarray:
    """Rotation matrix of a quaternion [w, x, y, z] (normalised first)."""
    w, x, y, z = np.asarray(quat, dtype=np.float64)
    return Rotation.from_quat([x, y, z, w]).as_matrix()


@dataclass(frozen=True)
class SensorSpec:
    """One sensor (see the module docstring for the types).

    Attributes:
        type: a key of ``SENSOR_DIMS``, or ``"unsupported"`` (a slot of NaN).
        body: body index the frame is fixed to (-1 only for ``"unsupported"``).
        pos: (3,) frame origin in the body's rest frame.
        rot: (3, 3) frame orientation in the body's rest frame.
        name: the sensor's name (MJCF ``name``), may be empty.
        zone: touch only: (shape, size) of the zone, a key of ``ZONE_SIZES`` and its sizes
            (MuJoCo's site ``size``: radius; radius, half length; semi-axes; half extents).
        ref: framepos / framequat only: (body, pos, rot) of the reference frame; None is the
            world.
        cutoff: > 0 clamps the values to [−cutoff, cutoff] (touch: [0, cutoff]), as MuJoCo;
            not applied to quaternions.
        dim: number of values (``SENSOR_DIMS[type]``; given for ``"unsupported"``).
        source: what the sensor was (e.g. the MJCF type), for messages.
        joint: jointpos / jointvel only: the joint's name (``Scene.add_joint``).
        actuator: actuatorfrc only: the actuator's index (``Scene.add_actuator``).
        offset: jointpos only: added to the joint coordinate (MuJoCo's qpos at load).
        gain: actuatorfrc only: the reading is ``gain`` times the actuator's force (an MJCF
            actuator mapped onto a preset with its gear rescaled by s reads s times abdsim's
            force, MuJoCo's value).
    """

    type: str
    body: int
    pos: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rot: np.ndarray = field(default_factory=lambda: np.eye(3))
    name: str = ""
    zone: tuple[str, np.ndarray] | None = None
    ref: tuple[int, np.ndarray, np.ndarray] | None = None
    cutoff: float = 0.0
    dim: int = 0
    source: str = ""
    joint: str = ""
    actuator: int = -1
    offset: float = 0.0
    gain: float = 1.0


class SensorSet:
    """The sensors of a Scene or World, in order, with MuJoCo's ``sensor_adr``/``sensor_dim``."""

    def __init__(self, specs: list[SensorSpec] | None = None) -> None:
        self._specs: list[SensorSpec] = []
        for s in specs or []:
            self.append(s)

    def add(
        self,
        type: str,
        body: int,
        pos: np.ndarray | tuple[float, float, float] = (0.0, 0.0, 0.0),
        quat: np.ndarray | tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0),
        *,
        name: str = "",
        zone: str = "sphere",
        size: np.ndarray | tuple[float, ...] | float | None = None,
        ref: tuple[int, np.ndarray, np.ndarray] | int | None = None,
        cutoff: float = 0.0,
    ) -> int:
        """Add a sensor on ``body`` at the site ``pos``/``quat`` (w-first) of its rest frame.

        Args:
            type: ``touch``, ``force``, ``torque``, ``accelerometer``, ``gyro``,
                ``velocimeter``, ``framepos`` or ``framequat``.
            body: body index (``handle.body(i)``).
            pos, quat: the site's pose in the body's rest frame.
            name: a name for ``World.sensor_names`` / ``sensor_index``.
            zone, size: touch only: the zone's shape and MuJoCo-style sizes (required).
            ref: framepos/framequat: a body index (its rest frame) or (body, pos, rot) of
                the reference frame; None: the world.
            cutoff: > 0 clamps the values (MuJoCo's ``cutoff``).

        Returns:
            The sensor's index.

        Raises:
            ValueError: an unknown type or zone, a bad size, pose or cutoff, a negative body.
        """
        if type in JOINT_TYPES:
            raise ValueError(f"a {type} sensor sits on a joint or actuator: use add_joint_sensor")
        if type not in SENSOR_DIMS:
            raise ValueError(f"sensor type must be one of {sorted(SENSOR_DIMS)}, got {type!r}")
        label = f"sensor {name or len(self._specs)!r} ({type})"
        pos_a = np.asarray(pos, dtype=np.float64).reshape(-1)
        quat_a = np.asarray(quat, dtype=np.float64).reshape(-1)
        if pos_a.shape != (3,) or quat_a.shape != (4,):
            raise ValueError(f"{label}: pos needs 3 values and quat 4 (w, x, y, z)")
        if not (np.isfinite(pos_a).all() and np.isfinite(quat_a).all()):
            raise ValueError(f"{label}: pos and quat must be finite")
        if not np.linalg.norm(quat_a) > 0:
            raise ValueError(f"{label}: quat must be non-zero")
        zone_spec = None
        if type == "touch":
            if zone not in ZONE_SIZES:
                raise ValueError(f"{label}: zone must be one of {sorted(ZONE_SIZES)}, got {zone!r}")
            if size is None:
                raise ValueError(f"{label}: a touch sensor needs the zone's size")
            s = np.atleast_1d(np.asarray(size, dtype=np.float64))
            k = ZONE_SIZES[zone]
            if s.size < k or not (np.isfinite(s[:k]).all() and (s[:k] > 0).all()):
                raise ValueError(f"{label}: a {zone} zone needs {k} positive size value(s)")
            zone_spec = (zone, s[:k].copy())
        ref_spec = None
        if ref is not None:
            if type not in ("framepos", "framequat"):
                raise ValueError(f"{label}: only framepos and framequat take a reference frame")
            if isinstance(ref, (int, np.integer)):
                ref_spec = (int(ref), np.zeros(3), np.eye(3))
            else:
                rb, rp, rr = ref
                ref_spec = (int(rb), np.asarray(rp, float).reshape(3), np.asarray(rr, float))
        if not (np.isfinite(cutoff) and cutoff >= 0):
            raise ValueError(f"{label}: cutoff must be finite and >= 0, got {cutoff!r}")
        return self.append(
            SensorSpec(
                type=type,
                body=int(body),
                pos=pos_a,
                rot=quat_wxyz_to_rotation(quat_a),
                name=name,
                zone=zone_spec,
                ref=ref_spec,
                cutoff=float(cutoff),
                dim=SENSOR_DIMS[type],
                source=type,
            )
        )

    def add_joint_sensor(
        self,
        type: str,
        target: str | int,
        *,
        name: str = "",
        offset: float = 0.0,
        cutoff: float = 0.0,
    ) -> int:
        """Add a ``jointpos`` or ``jointvel`` sensor on the joint named ``target``, or an
        ``actuatorfrc`` sensor on actuator index ``target``; ``offset`` is added to a
        jointpos reading (MuJoCo's qpos at load). Returns the sensor's index.

        Raises:
            ValueError: another type, a target of the wrong kind, a non-finite offset or a
                negative cutoff.
        """
        if type not in JOINT_TYPES:
            raise ValueError(
                f"joint sensor type must be one of {sorted(JOINT_TYPES)}, got {type!r}"
            )
        label = f"sensor {name or len(self._specs)!r} ({type})"
        if not (np.isfinite(offset) and np.isfinite(cutoff) and cutoff >= 0):
            raise ValueError(f"{label}: offset must be finite and cutoff finite and >= 0")
        if type == "actuatorfrc":
            if not isinstance(target, (int, np.integer)) or int(target) < 0:
                raise ValueError(f"{label}: the target is an actuator index >= 0, got {target!r}")
            spec = SensorSpec(type=type, body=-1, name=name, actuator=int(target))
        else:
            if not isinstance(target, str) or not target:
                raise ValueError(f"{label}: the target is a joint name, got {target!r}")
            spec = SensorSpec(type=type, body=-1, name=name, joint=target, offset=float(offset))
        return self.append(
            SensorSpec(**{**spec.__dict__, "cutoff": float(cutoff), "dim": 1, "source": type})
        )

    def append(self, spec: SensorSpec) -> int:
        """Add a ready SensorSpec (``dim`` filled in from its type); returns its index."""
        if spec.type != "unsupported":
            if spec.type not in SENSOR_DIMS:
                raise ValueError(f"unknown sensor type {spec.type!r}")
            if spec.type in JOINT_TYPES:
                pass  # on a joint or actuator (checked against the World's: check_joints)
            elif spec.body < 0 or (spec.ref is not None and spec.ref[0] < 0):
                raise ValueError(f"sensor {spec.name!r} ({spec.type}): body index must be >= 0")
            if spec.dim != SENSOR_DIMS[spec.type]:
                spec = SensorSpec(**{**spec.__dict__, "dim": SENSOR_DIMS[spec.type]})
        elif spec.dim < 1:
            raise ValueError(f"unsupported sensor {spec.name!r}: dim must be >= 1")
        self._specs.append(spec)
        return len(self._specs) - 1

    def extend(self, specs) -> None:
        for s in specs:
            self.append(s)

    @property
    def specs(self) -> list[SensorSpec]:
        return list(self._specs)

    @property
    def sensor_dim(self) -> np.ndarray:
        """(n_sensors,) int: values per sensor."""
        return np.array([s.dim for s in self._specs], dtype=np.int64)

    @property
    def sensor_adr(self) -> np.ndarray:
        """(n_sensors,) int: index of each sensor's first value in ``sensordata``."""
        dim = self.sensor_dim
        return np.concatenate([[0], np.cumsum(dim)[:-1]]).astype(np.int64) if len(dim) else dim

    @property
    def names(self) -> list[str]:
        return [s.name for s in self._specs]

    @property
    def needs_acceleration(self) -> bool:
        return any(s.type in ACCELERATION_TYPES for s in self._specs)

    def check_bodies(self, n_bodies: int) -> None:
        """ValueError naming the first sensor on a body index out of range."""
        for i, s in enumerate(self._specs):
            bodies = [s.body] + ([s.ref[0]] if s.ref is not None else [])
            if s.type == "unsupported" or s.type in JOINT_TYPES:
                continue
            if any(not 0 <= b < n_bodies for b in bodies):
                raise ValueError(
                    f"sensor {s.name or i!r} ({s.type}): body {bodies} out of range [0, {n_bodies})"
                )

    def check_joints(self, joint_names: list[str], n_actuators: int) -> None:
        """ValueError naming the first joint sensor whose joint or actuator is not there."""
        for i, s in enumerate(self._specs):
            if s.type in ("jointpos", "jointvel") and s.joint not in joint_names:
                raise ValueError(
                    f"sensor {s.name or i!r} ({s.type}): no joint named {s.joint!r} "
                    f"(joints: {joint_names})"
                )
            if s.type == "actuatorfrc" and not 0 <= s.actuator < n_actuators:
                raise ValueError(
                    f"sensor {s.name or i!r} (actuatorfrc): actuator {s.actuator} out of "
                    f"range [0, {n_actuators})"
                )

    def __len__(self) -> int:
        return len(self._specs)

    def __iter__(self):
        return iter(self._specs)

    def __repr__(self) -> str:
        return f"<SensorSet {len(self._specs)} sensor(s), {int(self.sensor_dim.sum())} values>"


class VelocityHistory:
    """The velocities before the World's last two steps, for the accelerations of the last
    step (BDF1, or BDF2 once it has a previous step: the first step after a reset is BDF1)."""

    def __init__(self) -> None:
        self._before: deque[np.ndarray] = deque(maxlen=2)
        self._steps_since_reset = 0

    def reset(self) -> None:
        """A new state (set_state): the next step is a BDF1 step."""
        self._before.clear()
        self._steps_since_reset = 0

    def before_step(self, q_dot: np.ndarray) -> None:
        self._before.append(np.array(q_dot, dtype=np.float64))
        self._steps_since_reset += 1

    def acceleration(self, q_dot: np.ndarray, dt: float, integrator: str) -> np.ndarray | None:
        """Generalized acceleration (n, 12) of the last step; None before any step."""
        q_dot = np.asarray(q_dot, dtype=np.float64)
        if not self._before:
            return None
        if integrator == "bdf2" and self._steps_since_reset >= 2 and len(self._before) == 2:
            older, last = self._before
            return (3.0 * q_dot - 4.0 * last + older) / (2.0 * dt)
        return (q_dot - self._before[-1]) / dt
