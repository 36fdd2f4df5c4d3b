"""What the URDF and MJCF loaders produce, and the pieces they share.

A loaded scene is a list of :class:`LoadedBody`: one affine body per *rigid group* of the
source (a Pinocchio joint with every link fixed to it; a MuJoCo weld group), whose surface is
the union of the group's collision geometries expressed in the group's frame, and whose mass
properties are exactly the source's (``assign_rigid_body``).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import trimesh

import abdsim
from abdsim.bridges._inertia_repair import bound_inertia, is_degenerate, surface_size
from abdsim.bridges._mesh_repair import closed_hull, drop_zero_area, is_proper_closed
from abdsim.geometry import validation as mesh_check

#: How a loaded body moves: ``fixed`` never moves (``is_fixed = 1``), ``kinematic`` follows a
#: prescribed trajectory (a driver sets its target every step), ``dynamic`` is simulated.
BodyKind = Literal["fixed", "kinematic", "dynamic"]
BODY_KINDS: tuple[str, ...] = ("fixed", "kinematic", "dynamic")


class LoaderError(ValueError):
    """A scene file that cannot be loaded as it is; the message names the element."""


# ---------------------------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------------------------
@dataclass
class LoadedBody:
    """One affine body of a loaded scene.

    Attributes:
        name: the source link (URDF) or body (MJCF) that names the rigid group.
        kind: ``"fixed"``, ``"kinematic"`` or ``"dynamic"``.
        geometry: a one-instance SimplicialComplex: rest vertices in the body frame, the
            instance ``transform`` = the body frame's world pose, ``velocity`` = dT/dt, exact
            mass properties in ``meta``.
        links: every source link / body merged into this one (the first is ``name``).
        geoms: the collision geometries (geom names) that make up the surface, in order.
        geom_ranges: vertex range ``(start, stop)`` of each geom in ``geometry``'s vertices.
        joint: the source joint that moves the group (None for fixed bodies).
        friction: sliding friction coefficient of the source (MJCF ``geom_friction[0]``,
            largest over the body's geoms), None where the source has none.
        parent: index of the body this one hangs from in the source's kinematic tree (None
            for a root or a body attached to the world).
    """

    name: str
    kind: str
    geometry: abdsim.SimplicialComplex
    links: tuple[str, ...] = ()
    geoms: tuple[str, ...] = ()
    geom_ranges: dict[str, tuple[int, int]] = field(default_factory=dict)
    joint: str | None = None
    friction: float | None = None
    parent: int | None = None

    @property
    def transform(self) -> np.ndarray:
        """World pose of the body frame, (4, 4)."""
        return np.array(self.geometry.transforms[0])

    @property
    def velocity(self) -> np.ndarray:
        """dT/dt of the body frame, (4, 4)."""
        return np.array(self.geometry.instances["velocity"][0])


@dataclass
class JointInfo:
    """A source joint between two loaded bodies, at the loaded configuration (world frame).

    Attributes:
        name: the source joint's name.
        type: ``"revolute"``, ``"prismatic"``, ``"ball"``, ``"free"`` or ``"other"``.
        parent: body index of the nearest loaded ancestor (None: the world).
        child: body index the joint moves.
        anchor: world position of the joint origin.
        axis: world unit axis (revolute, prismatic), else None.
        source_id: the joint's id in the source model (MuJoCo joint id; Pinocchio joint
            index), None where unknown.
    """

    name: str
    type: str
    parent: int | None
    child: int
    anchor: np.ndarray
    axis: np.ndarray | None = None
    source_id: int | None = None


@dataclass
class Ground:
    """An infinite ground plane ``normal · x = height`` (MJCF ``plane`` geoms)."""

    height: float
    normal: np.ndarray
    name: str
    friction: float | None = None


@dataclass
class LoadResult:
    """A loaded URDF / MJCF scene: bodies (index = body index), settings and the source model.

    Attributes:
        source: the file that was loaded.
        format: ``"urdf"`` or ``"mjcf"``.
        bodies: the loaded bodies; ``bodies[i]`` is body ``i`` of :attr:`scene`.
        dt: time step of the source (MJCF ``opt.timestep``), None where it has none.
        gravity: gravity of the source (MJCF ``opt.gravity``), None where it has none.
        grounds: ground planes (MJCF ``plane`` geoms).
        joints: the source joints between loaded bodies (for joint energies / inspection).
        model: the source model (``pinocchio.Model`` or ``mujoco.MjModel``).
        collision_model: Pinocchio's ``GeometryModel`` (URDF only).
        q: the source configuration the bodies were placed at (Pinocchio ``q`` / MuJoCo
            ``qpos``).
        source_map: source rigid group → body index (URDF: Pinocchio joint id; MJCF: MuJoCo
            body id of the weld group's root; MJCF world geoms are not in it).
        notes: what was skipped or approximated while loading (also issued as warnings).
        contact_damping: the contact damping ratio ζ the source asks for (MJCF ``solref``'s
            damping ratio; ``SceneSettings.contact_damping``), None where it says nothing.
        sensors: the source's sensors (``abdsim.sim.sensors.SensorSpec``, MJCF ``<sensor>``),
            added to :attr:`scene`'s ``sensors``.
        contact_rules: the source's pairwise contact filter and friction
            (``abdsim.bridges._contact_rules.ContactRules``; None: every pair collides), written
            into the scene's ``contact_table`` with body ``i`` as contact element ``i``.
        articulated: True (the loaders' default, ``kinematic=False``): jointed bodies are
            dynamic and :attr:`scene` joins them (``bridges/articulated.py``); False:
            ``kinematic=True``, they are scripted (``RobotDriver`` / ``MjcfDriver``).
        actuators: the MJCF actuators abdsim models (``ActuatorInfo``, MuJoCo order), the
            entries of ``world.ctrl`` of :meth:`make_world` (``bridges/_mjcf_actuators.py``).
    """

    source: Path
    format: str
    bodies: list[LoadedBody]
    dt: float | None = None
    gravity: np.ndarray | None = None
    grounds: list[Ground] = field(default_factory=list)
    joints: list[JointInfo] = field(default_factory=list)
    model: Any = None
    collision_model: Any = None
    q: np.ndarray | None = None
    source_map: dict[int, int] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    sensors: list[Any] = field(default_factory=list)
    contact_rules: Any = None
    contact_damping: float | None = None
    articulated: bool = False
    actuators: list[Any] = field(default_factory=list)
    _scene: Any = field(default=None, repr=False)

    # -- lookup -------------------------------------------------------------------------------
    @property
    def names(self) -> list[str]:
        """Body names, in body-index order."""
        return [b.name for b in self.bodies]

    @property
    def geometries(self) -> list[abdsim.SimplicialComplex]:
        """The bodies' SimplicialComplexes, in body-index order."""
        return [b.geometry for b in self.bodies]

    def index(self, name: str) -> int:
        """Body index of a body, or of the body a source link / body / geom was merged into."""
        for i, b in enumerate(self.bodies):
            if name == b.name:
                return i
        for i, b in enumerate(self.bodies):
            if name in b.links or name in b.geoms:
                return i
        raise KeyError(f"no body, link or geom named {name!r}; bodies: {self.names}")

    def indices(self, kind: str) -> list[int]:
        """Body indices of every body of the given kind."""
        if kind not in BODY_KINDS:
            raise ValueError(f"kind must be one of {BODY_KINDS}, got {kind!r}")
        return [i for i, b in enumerate(self.bodies) if b.kind == kind]

    def transforms(self) -> np.ndarray:
        """Initial world poses of all bodies, (n, 4, 4)."""
        return np.array([b.transform for b in self.bodies]).reshape(-1, 4, 4)

    @property
    def ground(self) -> Ground | None:
        """The first ground plane, or None."""
        return self.grounds[0] if self.grounds else None

    # -- scene ----------------------------------------------------------------------------
    @property
    def scene(self) -> Any:
        """A ready ``abdsim.Scene`` holding every body (built on first access).

        Body ``i`` of the scene is ``bodies[i]``; ``dt`` and ``gravity`` are the source's
        (MJCF) or the Scene's defaults (URDF). See :meth:`build_scene` for other settings.
        """
        if self._scene is None:
            self.build_scene()
        return self._scene

    def build_scene(self, **settings: Any) -> Any:
        """Build (and keep as :attr:`scene`) an ``abdsim.Scene`` with every body.

        ``settings`` are Scene settings overriding the source's (``dt=...``, ...). An
        articulated result (the default) joins its bodies by the source's joints, with their
        physics and the MJCF joint actuators (``build_articulated_scene``).
        """
        if self.articulated:
            from abdsim.bridges.articulated import build_articulated_scene

            self._scene = build_articulated_scene(self, **settings)
        else:
            from abdsim.bridges._world_adapter import build_scene

            self._scene = build_scene(self, **settings)
        return self._scene

    def make_world(self, **settings: Any) -> Any:
        """A World of a new :meth:`build_scene`. Articulated: a
        :class:`abdsim.bridges.RobotWorld` (``world.ctrl`` = :attr:`actuators`, site
        actuators included); kinematic: an ``abdsim.World`` whose kinematic bodies are held
        at their loaded poses until a driver moves them."""
        scene = self.build_scene(**settings)
        if self.articulated:
            from abdsim.bridges.robot_world import RobotWorld

            return RobotWorld(scene, self.actuators)
        from abdsim.bridges._world_adapter import make_world

        return make_world(self, scene)

    # -- joints and actuators -------------------------------------------------------------
    @property
    def joint_names(self) -> list[str]:
        """Names of the abdsim joints, in the order of ``world.joint_positions()`` (free
        joints are bodies' states, not abdsim joints: see :meth:`qpos_from_world`)."""
        return [j.name for j in self.joints if j.type != "free"]

    @property
    def actuator_names(self) -> list[str]:
        """Names of the modelled actuators, in the order of ``world.ctrl``."""
        return [a.name for a in self.actuators]

    @property
    def actuator_ids(self) -> np.ndarray:
        """MuJoCo actuator id of each ``world.ctrl`` entry: ``world.ctrl[:] =
        data.ctrl[result.actuator_ids]``."""
        return np.array([a.mj_id for a in self.actuators], dtype=np.int64)

    def qpos_from_world(self, world: Any) -> np.ndarray:
        """The source configuration of ``world``'s state: MuJoCo ``qpos`` (MJCF) or
        Pinocchio ``q`` (URDF); see ``bridges/_joint_map.py`` for the conventions."""
        from abdsim.bridges import _joint_map

        return _joint_map.qpos_from_joint_positions(self, world.joint_positions(), world)

    def qvel_from_world(self, world: Any) -> np.ndarray:
        """The source velocity of ``world``'s state: MuJoCo ``qvel`` or Pinocchio ``v``."""
        from abdsim.bridges import _joint_map

        return _joint_map.qvel_from_joint_velocities(self, world.joint_velocities(), world)

    def qpos_from_joint_positions(self, positions: Any) -> np.ndarray:
        """MuJoCo ``qpos`` / Pinocchio ``q`` from ``world.joint_positions()``-shaped values
        (free bodies keep their loaded coordinates)."""
        from abdsim.bridges import _joint_map

        return _joint_map.qpos_from_joint_positions(self, positions)

    def joint_positions_from_qpos(self, qpos: Any) -> np.ndarray:
        """``world.joint_positions()``-shaped values from MuJoCo ``qpos`` / Pinocchio ``q``."""
        from abdsim.bridges import _joint_map

        return _joint_map.joint_positions_from_qpos(self, qpos)

    def qvel_from_joint_velocities(self, velocities: Any) -> np.ndarray:
        """MuJoCo ``qvel`` / Pinocchio ``v`` from ``world.joint_velocities()``-shaped values
        (free bodies' entries zero)."""
        from abdsim.bridges import _joint_map

        return _joint_map.qvel_from_joint_velocities(self, velocities)

    def joint_velocities_from_qvel(self, qvel: Any) -> np.ndarray:
        """``world.joint_velocities()``-shaped values from MuJoCo ``qvel`` / Pinocchio ``v``."""
        from abdsim.bridges import _joint_map

        return _joint_map.joint_velocities_from_qvel(self, qvel)

    def set_world_state(self, world: Any, qpos: Any, qvel: Any = None) -> None:
        """Put ``world`` at MuJoCo ``qpos``/``qvel`` (Pinocchio ``q``/``v``) through the
        source's forward kinematics (every loaded body's pose and velocity)."""
        from abdsim.bridges import _joint_map

        _joint_map.set_world_state(self, world, qpos, qvel)

    def __repr__(self) -> str:
        kinds = {k: len(self.indices(k)) for k in BODY_KINDS}
        return (
            f"<LoadResult {self.format} {self.source.name!r}: {len(self.bodies)} bodies "
            f"{kinds}, grounds={len(self.grounds)}>"
        )


# ---------------------------------------------------------------------------------------------
# Surfaces
# ---------------------------------------------------------------------------------------------
@dataclass
class Surface:
    """A closed triangle surface of one collision geometry, in its body's frame."""

    name: str
    vertices: np.ndarray
    triangles: np.ndarray


def primitive_surface(kind: str, size: Sequence[float], name: str) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of a primitive centred at the origin (axis along z).

    ``size``: box half-extents (3); sphere radius (1); capsule / cylinder radius and
    half-length (2); ellipsoid radii (3).
    """
    s = [float(x) for x in size]
    if not all(np.isfinite(x) and x > 0 for x in s):
        raise LoaderError(f"geometry {name!r}: {kind} size must be positive, got {s}")
    if kind == "box":
        sc = abdsim.geometry.box((2 * s[0], 2 * s[1], 2 * s[2]))
    elif kind in ("sphere", "capsule", "cylinder"):
        # Round shapes are tessellated at unit radius and scaled: built at their own size, a
        # radius <= 1 mm merged vertices at the tessellator's absolute tolerance (open mesh).
        r = s[0]
        if kind == "sphere":
            sc = abdsim.geometry.sphere(1.0, subdivisions=2)
        elif kind == "capsule":
            sc = abdsim.geometry.capsule(1.0, 2 * s[1] / r)
        else:
            sc = abdsim.geometry.cylinder(1.0, 2 * s[1] / r)
        return sc.positions * r, sc.triangles.copy()
    elif kind == "ellipsoid":
        unit = abdsim.geometry.sphere(1.0, subdivisions=2)
        return unit.positions * np.asarray(s[:3]), unit.triangles.copy()
    else:
        raise LoaderError(f"geometry {name!r}: unsupported primitive {kind!r}")
    return sc.positions.copy(), sc.triangles.copy()


def closed_surface(
    name: str, vertices: np.ndarray, triangles: np.ndarray, open_mesh: str, notes: list[str]
) -> tuple[np.ndarray, np.ndarray]:
    """The mesh itself if it is a closed, outward-oriented surface; else repaired or rejected.

    Repairs, in order: drop zero-area triangles (a note); merge duplicate vertices (STL-style
    triangle soups); fix winding and orientation; then, if ``open_mesh == "hull"``, the closed
    convex hull (a note says so; the loader warns once per note).
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = drop_zero_area(name, v, triangles, notes)
    if _is_closed_outward(v, f):
        return v, f
    mesh = trimesh.Trimesh(v, f, process=True, validate=True)
    if mesh.is_watertight:
        trimesh.repair.fix_normals(mesh)
        if mesh.is_winding_consistent and mesh.volume > 0:
            repaired = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces)
            if is_proper_closed(*repaired):  # merging vertices can leave zero-area slivers
                return repaired
    if open_mesh == "hull":
        # The loader warns once for every note (bridges/_mesh_repair.py: a closed hull).
        notes.append(
            f"geometry {name!r} is not a closed surface ({len(f)} triangles): using its convex "
            "hull as the body's surface"
        )
        return closed_hull(name, v)
    raise LoaderError(
        f"geometry {name!r} is not a closed, consistently oriented surface (an affine body "
        "needs a solid); pass open_mesh='hull' to use its convex hull"
    )


def _is_closed_outward(v: np.ndarray, f: np.ndarray) -> bool:
    if len(f) < 4:
        return False
    try:
        mesh_check.check_closed_oriented(f)
    except ValueError:
        return False
    p = v[f]
    signed = np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum()
    return bool(signed > 0)


def transform_points(T: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Apply a 4x4 (or 3x4) transform to (n, 3) points."""
    return points @ T[:3, :3].T + T[:3, 3]


# ---------------------------------------------------------------------------------------------
# Bodies
# ---------------------------------------------------------------------------------------------
def make_body(
    name: str,
    kind: str,
    surfaces: Sequence[Surface],
    transform: np.ndarray,
    *,
    kappa: float,
    constitution: str,
    mass: tuple[float, np.ndarray, np.ndarray] | None,
    velocity: np.ndarray | None = None,
    links: Sequence[str] = (),
    joint: str | None = None,
    friction: float | None = None,
    mass_density: float = 1e3,
    notes: list[str] | None = None,
) -> LoadedBody:
    """Build one body: merged surfaces, constitution, exact mass properties, pose, velocity.

    ``mass = (m, centre, inertia about centre)`` in the body frame; None gives the mass of
    the surface at ``mass_density`` (used for fixed bodies, whose mass plays no role). A
    moving body whose inertia is degenerate gets ``bound_inertia`` and a line in ``notes``.
    """
    if kind not in BODY_KINDS:
        raise ValueError(f"body kind must be one of {BODY_KINDS}, got {kind!r}")
    if not surfaces:
        raise LoaderError(f"body {name!r} has no collision geometry")
    verts, tris, ranges, offset = [], [], {}, 0
    for s in surfaces:
        verts.append(s.vertices)
        tris.append(np.asarray(s.triangles, dtype=np.int64) + offset)
        ranges[s.name] = (offset, offset + len(s.vertices))
        offset += len(s.vertices)
    try:
        sc = abdsim.geometry.triangle_mesh(np.concatenate(verts), np.concatenate(tris))
        sc.transforms = np.asarray(transform, dtype=np.float64).reshape(1, 4, 4)
        abdsim.AffineBodyConstitution(constitution).apply_to(sc, kappa, mass_density=mass_density)
    except ValueError as e:
        raise LoaderError(f"body {name!r} (geoms {[s.name for s in surfaces]}): {e}") from e
    if mass is not None:
        m, c, inertia = mass
        if kind == "fixed" and is_degenerate(inertia):
            mass = None  # a fixed body's mass plays no role: keep its surface's
        elif is_degenerate(inertia) or not m > 0:
            # A moving group still degenerate after merging its fixed links: bounded
            # (bridges/_inertia_repair.py), never a refusal of the robot.
            m, inertia = bound_inertia(m, inertia, surface_size([s.vertices for s in surfaces]))
            note = (
                f"body {name!r} (links {list(links) or [name]}): degenerate inertia "
                f"(mass {mass[0]:g} kg, moments {np.linalg.eigvalsh(mass[2]).tolist()}); "
                f"bounded to principal moments {np.linalg.eigvalsh(inertia).tolist()}"
            )
            if notes is not None:
                notes.append(note)
    if mass is not None:
        try:
            abdsim.constitution.check_inertia(
                np.asarray(inertia, dtype=np.float64), what=f"inertia of body {name!r}"
            )
            abdsim.assign_rigid_body(sc, m, c, inertia)
        except ValueError as e:
            raise LoaderError(f"body {name!r} (links {list(links) or [name]}): {e}") from e
    if kind == "fixed":
        sc.instances["is_fixed"] = np.int32(1)
    if velocity is not None and kind != "fixed":
        sc.instances["velocity"] = np.asarray(velocity, dtype=np.float64).reshape(1, 4, 4)
    return LoadedBody(
        name=name,
        kind=kind,
        geometry=sc,
        links=tuple(links) or (name,),
        geoms=tuple(s.name for s in surfaces),
        geom_ranges=ranges,
        joint=joint,
        friction=friction,
    )


def combine_inertias(
    parts: Sequence[tuple[float, np.ndarray, np.ndarray]],
) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre and inertia about the centre of rigidly joined parts (same frame)."""
    parts = [(float(m), np.asarray(c, float), np.asarray(i, float)) for m, c, i in parts if m > 0]
    if not parts:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    if len(parts) == 1:
        return parts[0]
    total = sum(m for m, _, _ in parts)
    centre = sum(m * c for m, c, _ in parts) / total
    inertia = np.zeros((3, 3))
    for m, c, i in parts:
        d = c - centre
        inertia += i + m * (d @ d * np.eye(3) - np.outer(d, d))
    return total, centre, inertia


# ---------------------------------------------------------------------------------------------
# Rotations and velocities
# ---------------------------------------------------------------------------------------------
def skew(w: np.ndarray) -> np.ndarray:
    """[w]x, the cross-product matrix."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def velocity_matrix(
    rotation: np.ndarray, omega_world: np.ndarray, v_world: np.ndarray
) -> np.ndarray:
    """dT/dt of a rigid motion: top-left ``[ω]x R``, column 3 the origin's velocity."""
    dT = np.zeros((4, 4))
    dT[:3, :3] = skew(np.asarray(omega_world, float)) @ np.asarray(rotation, float)
    dT[:3, 3] = v_world
    return dT


def quat_wxyz_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a (w, x, y, z) quaternion (normalised first)."""
    w, x, y, z = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def pose_matrix(rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    """4x4 homogeneous transform."""
    T = np.eye(4)
    T[:3, :3] = rotation
    T[:3, 3] = translation
    return T


def check_file(path: str | Path, what: str, suffixes: Sequence[str]) -> Path:
    """An existing file, or a clear FileNotFoundError / LoaderError."""
    p = Path(path).expanduser()
    if not p.exists():
        raise FileNotFoundError(f"{what} file not found: {p}")
    if not p.is_file():
        raise LoaderError(f"{what} path is not a file: {p}")
    if suffixes and p.suffix.lower() not in suffixes:
        warnings.warn(f"{what} file {p.name!r} does not end in {'/'.join(suffixes)}", stacklevel=3)
    return p.resolve()
