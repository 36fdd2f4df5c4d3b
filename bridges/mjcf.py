"""MJCF scenes as affine bodies, through MuJoCo.

MuJoCo compiles the file (``mujoco.MjModel.from_xml_path``); abdsim reads the compiled model:

* One affine body per **weld group**: a body with joints plus every descendant welded to it
  without joints (``body_weldid``). Vertices are in the group root's body frame, the pose is
  the root's ``xpos/xmat``, and the mass properties are MuJoCo's exactly: ``body_mass``,
  ``body_ipos`` and ``body_inertia`` (principal moments in the frame ``body_iquat``, w-first)
  → the full inertia tensor in the body frame (a group of several bodies gets their exact
  combination). A group whose root has a ``free`` joint is ``dynamic``; one on
  ``hinge``/``slide``/``ball`` joints is ``kinematic`` (:class:`abdsim.bridges.MjcfDriver`).
* Articulated (the default), a body moved by several joints (planar roots, two- and
  three-hinge hips) hangs from its parent through a chain of joint frames, one MuJoCo joint
  each, that collide with nothing and carry a small share of its mass
  (``bridges/_joint_frames.py``); joint names, order and coordinates stay MuJoCo's.
* Every geom fixed to the world (on the world body or on a body welded to it) is its own
  ``fixed`` body, in the geom's frame. z-up ``plane`` geoms become :class:`Ground` planes;
  other planes (walls, tilted) fixed thin boxes and height fields fixed closed solids
  (``bridges/_mjcf_geoms.py``).
* Contact follows MuJoCo's filter (contype/conaffinity, parent–child, ``<exclude>``,
  ``<pair>``) and per-pair friction (max rule): ``LoadResult.contact_rules``
  (``bridges/_contact_rules.py``). Tendons, equality constraints and actuators are named in
  the notes (not simulated).
* Geom shapes: box, sphere, capsule, cylinder, ellipsoid, mesh. MuJoCo re-centres and
  rotates meshes into their inertial frame and folds that into ``geom_pos/geom_quat``, so the
  vertices are ``geom pose × mesh_vert``. Note that MuJoCo collides with a mesh's convex hull
  while abdsim uses the mesh itself.
* Geoms that collide with nothing (``contype = conaffinity = 0``, MJCF's visual geoms) are
  skipped unless ``include_visual=True``.
* The first keyframe (if any) sets the initial ``qpos``/``qvel``: a body's ``velocity`` is
  dT/dt from MuJoCo's body velocity (``mj_objectVelocity``; for a free joint that is
  ``qvel = [v_world, ω_body]``, Ȧ = [ω_world]× A).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from abdsim.bridges._bodies import (
    Ground,
    JointInfo,
    LoadedBody,
    LoaderError,
    LoadResult,
    Surface,
    check_file,
    closed_surface,
    combine_inertias,
    make_body,
    pose_matrix,
    primitive_surface,
    quat_wxyz_to_matrix,
    transform_points,
    velocity_matrix,
)
from abdsim.bridges._contact_rules import (
    exclude_touching,
    exclude_touching_ground,
    mjcf_rules,
)
from abdsim.bridges._inertia_proxy import inertia_box
from abdsim.bridges._joint_frames import compound_note, joint_frames
from abdsim.bridges._mjcf_actuators import read_actuators
from abdsim.bridges._mjcf_geoms import heightfield_surface, plane_box_size
from abdsim.bridges._mjcf_unsupported import unsimulated_notes
from abdsim.bridges.articulated import check_articulation

_PRIMITIVES = {"box": 3, "sphere": 1, "capsule": 2, "cylinder": 2, "ellipsoid": 3}


def load_mjcf(
    path: str | os.PathLike,
    kappa: float = 1e8,
    *,
    keyframe: int | str | None = 0,
    constitution: str = "OrthoPotential",
    include_visual: bool = False,
    open_mesh: str = "hull",
    skip_unsupported: bool = False,
    kinematic: bool = False,
) -> LoadResult:
    """Load an MJCF scene as affine bodies: by default a dynamic articulation.

    Args:
        path: the MJCF (MuJoCo XML) file.
        kappa: shape stiffness κ of every body (Pa).
        keyframe: keyframe (index or name) for the initial ``qpos``/``qvel`` when the model
            has keyframes; None uses ``qpos0`` and zero velocity.
        constitution: ``"OrthoPotential"`` or ``"ARAP"``.
        include_visual: also make surfaces of geoms that collide with nothing.
        open_mesh: a mesh that is not a closed surface: ``"hull"`` (convex hull, with a
            warning) or ``"error"``.
        skip_unsupported: skip (with a warning) geoms of unsupported types (hfield, sdf, a
            plane on a moving body) instead of raising.
        kinematic: False (default): bodies on hinge / slide / ball joints are dynamic and
            ``result.scene`` joins them with the file's joint physics and actuators
            (``bridges/articulated.py``, ``bridges/_mjcf_actuators.py``); True: they are
            kinematic, scripted by :class:`abdsim.bridges.MjcfDriver`.

    Returns:
        A :class:`LoadResult` with ``dt = opt.timestep``, ``gravity = opt.gravity``, the
        ground planes, per-body friction (``geom_friction[:, 0]``) and ``model`` (the
        ``mujoco.MjModel``).

    Raises:
        FileNotFoundError: the file, or a mesh file it names, does not exist.
        LoaderError (a ValueError): MuJoCo rejects the file (its message names the element;
            this covers malformed XML and non-physical inertias), an unsupported geom, a
            dynamic body without collision geometry, an unknown keyframe.
    """
    import mujoco

    if open_mesh not in ("hull", "error"):
        raise ValueError(f"open_mesh must be 'hull' or 'error', got {open_mesh!r}")
    mjcf = check_file(path, "MJCF", (".xml", ".mjcf"))
    model = _compile(mujoco, mjcf)
    data = mujoco.MjData(model)
    if keyframe is not None and model.nkey > 0:
        mujoco.mj_resetDataKeyframe(model, data, _keyframe_id(mujoco, model, keyframe))
    mujoco.mj_forward(model, data)

    loader = _MjcfLoader(
        mujoco, model, data, kappa, constitution, open_mesh, notes=[], articulated=not kinematic
    )
    bodies, grounds, source_map, joints = loader.run(include_visual, skip_unsupported)
    # <sensor> elements (bridges/mjcf_sensors.py): MuJoCo's layout, unsupported ones in notes.
    from abdsim.bridges.mjcf_sensors import actuator_sensors, read_sensors

    sensors = read_sensors(loader, source_map)
    # MuJoCo's collision filter and per-pair friction (bridges/_contact_rules.py).
    geom_ids = {loader.geom_name(g): g for g in range(model.ngeom)}
    rules = mjcf_rules(mujoco, model, bodies, geom_ids, [geom_ids[gr.name] for gr in grounds])
    loader.notes.extend(unsimulated_notes(mujoco, model, articulated=not kinematic))
    actuators = []
    if not kinematic:  # bridges/_mjcf_actuators.py: what each actuator becomes, or why not
        bodies = [_dynamic(b) for b in bodies]
        # Jointed bodies that touch the world's or each other's geometry at load (a cart
        # around its rails) start in contact MuJoCo resolves softly: they never collide.
        exclude_touching(bodies, rules, loader.notes)
        exclude_touching_ground(bodies, grounds, rules, loader.notes)
        loaded = {j.name for j in joints if j.type in ("revolute", "prismatic")}
        actuators = read_actuators(
            mujoco, model, source_map, loader.pose_in_root, loaded, loader.notes
        )
        sensors = actuator_sensors(sensors, actuators, model, loader.notes)
    contact_damping = solref_damping(model, loader.notes)
    for note in loader.notes:
        warnings.warn(note, stacklevel=2)
    if not bodies and not grounds:
        raise LoaderError(f"MJCF {mjcf} has no collision geometry: nothing to simulate")
    result = LoadResult(
        source=mjcf,
        format="mjcf",
        bodies=bodies,
        dt=float(model.opt.timestep),
        gravity=np.array(model.opt.gravity, dtype=np.float64),
        grounds=grounds,
        joints=joints,
        model=model,
        q=np.array(data.qpos),
        source_map=source_map,
        notes=loader.notes,
        sensors=sensors,
        contact_rules=rules,
        contact_damping=contact_damping,
        articulated=not kinematic,
        actuators=actuators,
    )
    if not kinematic:
        check_articulation(result)  # a clear error now rather than at result.scene
    return result


def _dynamic(body: LoadedBody) -> LoadedBody:
    return replace(body, kind="dynamic") if body.kind == "kinematic" else body


def solref_damping(model, notes: list[str]) -> float | None:
    """abdsim's contact damping ratio ζ from the colliding geoms' ``solref``.

    MuJoCo's standard ``solref`` (time constant > 0, damping ratio) makes each contact a
    spring-damper with that damping ratio; abdsim's ``contact_damping`` is the damping ratio
    of a dashpot on the same normal motion against IPC's barrier, so the ratio maps and the
    time constant does not (the barrier's stiffness is IPC's). Direct ``solref`` (negative:
    stiffness, damping) and per-``<pair>`` values have no such meaning and are noted. With
    different ratios on different geoms the mean is taken (MuJoCo mixes each pair's).
    None where nothing collides.
    """
    colliding = [
        g
        for g in range(model.ngeom)
        if model.geom_contype[g] != 0 or model.geom_conaffinity[g] != 0
    ]
    if not colliding:
        return None
    solref = np.asarray(model.geom_solref, dtype=np.float64)[colliding]
    standard = solref[:, 0] > 0
    if not standard.all():
        notes.append(
            f"contact: {int((~standard).sum())} geom(s) use direct solref (-stiffness, "
            "-damping), which has no damping-ratio meaning: contact_damping left at the "
            "scene's default"
        )
        return None
    ratios = solref[:, 1]
    zeta = float(ratios.mean())
    spread = "" if np.ptp(ratios) == 0 else f" (mean of {ratios.min():g}..{ratios.max():g})"
    notes.append(
        f"contact: solref damping ratio {zeta:g}{spread} -> contact_damping = {zeta:g}; "
        f"solref time constant(s) {sorted(set(solref[:, 0].tolist()))} s not mapped "
        "(abdsim's barrier stiffness is IPC's: contact_stiffness, d_hat)"
    )
    if model.npair:
        notes.append(f"contact: {model.npair} <pair> element(s): their solref is not mapped")
    return zeta


def _compile(mujoco, mjcf: Path):
    try:
        return mujoco.MjModel.from_xml_path(str(mjcf))
    except ValueError as e:
        message = str(e).strip()
        lowered = message.lower()
        if any(k in lowered for k in ("resource not found", "could not open", "error opening")):
            raise FileNotFoundError(f"MJCF {mjcf}: {message}") from e
        raise LoaderError(f"MuJoCo could not load MJCF {mjcf}: {message}") from e


def _keyframe_id(mujoco, model, keyframe: int | str) -> int:
    if isinstance(keyframe, str):
        k = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, keyframe)
        if k < 0:
            raise LoaderError(f"MJCF has no keyframe named {keyframe!r}")
        return k
    if not 0 <= int(keyframe) < model.nkey:
        raise LoaderError(f"keyframe {keyframe} out of range: the model has {model.nkey}")
    return int(keyframe)


def body_local_inertia(model, b: int) -> tuple[float, np.ndarray, np.ndarray]:
    """MuJoCo body ``b``'s mass, centre and full inertia tensor about the centre (body frame)."""
    R = quat_wxyz_to_matrix(model.body_iquat[b])
    inertia = R @ np.diag(np.asarray(model.body_inertia[b], dtype=np.float64)) @ R.T
    return float(model.body_mass[b]), np.array(model.body_ipos[b], dtype=np.float64), inertia


class _MjcfLoader:
    def __init__(self, mujoco, model, data, kappa, constitution, open_mesh, notes, articulated):
        self.articulated = articulated
        self.mj = mujoco
        self.m = model
        self.d = data
        self.kappa = kappa
        self.constitution = constitution
        self.open_mesh = open_mesh
        self.notes: list[str] = notes

    # -- names --------------------------------------------------------------------------------
    def body_name(self, b: int) -> str:
        return self.m.body(b).name or f"body{b}"

    def geom_name(self, g: int) -> str:
        return self.m.geom(g).name or f"{self.body_name(int(self.m.geom_bodyid[g]))}/geom{g}"

    def geom_type(self, g: int) -> str:
        return self.mj.mjtGeom(int(self.m.geom_type[g])).name[len("mjGEOM_") :].lower()

    # -- frames -------------------------------------------------------------------------------
    def local_pose(self, b: int) -> np.ndarray:
        return pose_matrix(quat_wxyz_to_matrix(self.m.body_quat[b]), self.m.body_pos[b])

    def pose_in_root(self, b: int, root: int) -> np.ndarray:
        """Pose of body ``b`` in the frame of its weld root (exact, from the model)."""
        T = np.eye(4)
        while b != root:
            T = self.local_pose(b) @ T
            b = int(self.m.body_parentid[b])
        return T

    def geom_local_pose(self, g: int) -> np.ndarray:
        return pose_matrix(quat_wxyz_to_matrix(self.m.geom_quat[g]), self.m.geom_pos[g])

    # -- geoms --------------------------------------------------------------------------------
    def geom_shape(self, g: int) -> tuple[np.ndarray, np.ndarray]:
        """Vertices (geom frame) and triangles of geom ``g``."""
        kind, name = self.geom_type(g), self.geom_name(g)
        if kind in _PRIMITIVES:
            return primitive_surface(kind, self.m.geom_size[g][: _PRIMITIVES[kind]], name)
        if kind == "plane":  # a wall (bridges/_mjcf_geoms.py): a fixed thin box
            half, centre = plane_box_size(self.m.geom_size[g], float(self.m.stat.extent))
            v, f = primitive_surface("box", half, name)
            return v + centre, f
        if kind == "hfield":
            h = int(self.m.geom_dataid[g])
            nrow, ncol = int(self.m.hfield_nrow[h]), int(self.m.hfield_ncol[h])
            adr = int(self.m.hfield_adr[h])
            data = self.m.hfield_data[adr : adr + nrow * ncol]
            return heightfield_surface(nrow, ncol, self.m.hfield_size[h], data)
        mesh = int(self.m.geom_dataid[g])
        va, vn = int(self.m.mesh_vertadr[mesh]), int(self.m.mesh_vertnum[mesh])
        fa, fn = int(self.m.mesh_faceadr[mesh]), int(self.m.mesh_facenum[mesh])
        v = np.asarray(self.m.mesh_vert[va : va + vn], dtype=np.float64)
        f = np.asarray(self.m.mesh_face[fa : fa + fn], dtype=np.int64)
        label = f"{name} (mesh {self.m.mesh(mesh).name!r})"
        return closed_surface(label, v, f, self.open_mesh, self.notes)

    def classify_geoms(self, include_visual: bool, skip_unsupported: bool):
        """Collision geoms per weld root, world-fixed geoms, and ground planes."""
        m, weld = self.m, self.m.body_weldid
        per_root: dict[int, list[int]] = {}
        fixed: list[int] = []
        grounds: list[Ground] = []
        for g in range(m.ngeom):
            b = int(m.geom_bodyid[g])
            root = int(weld[b])
            kind = self.geom_type(g)
            if not include_visual and m.geom_contype[g] == 0 and m.geom_conaffinity[g] == 0:
                continue
            if kind == "plane" and root == 0:
                n = np.array(self.d.geom_xmat[g]).reshape(3, 3)[:, 2]
                height = float(n @ self.d.geom_xpos[g])
                if np.allclose(n, [0.0, 0.0, 1.0], atol=1e-12) and all(
                    gr.height == height for gr in grounds
                ):
                    friction = float(m.geom_friction[g, 0])
                    grounds.append(Ground(height, n, self.geom_name(g), friction))
                    continue
                self.notes.append(
                    f"plane {self.geom_name(g)!r} (normal {n.round(6).tolist()}) is not the z-up "
                    "ground: it becomes a fixed thin box under its rectangle"
                )
            if kind not in _PRIMITIVES and kind not in ("mesh", "hfield", "plane"):
                msg = (
                    f"geom {self.geom_name(g)!r} (body {self.body_name(b)!r}): unsupported geom "
                    f"type {kind!r} (supported: {sorted(_PRIMITIVES)}, mesh, hfield, and plane "
                    "on the world body)"
                )
                if not skip_unsupported:
                    raise LoaderError(msg)
                self.notes.append(msg + "; skipped")
                continue
            if root == 0:
                fixed.append(g)
            else:
                per_root.setdefault(root, []).append(g)
        return per_root, fixed, grounds

    # -- bodies -------------------------------------------------------------------------------
    def group_kind(self, root: int) -> tuple[str, str | None]:
        m = self.m
        adr, num = int(m.body_jntadr[root]), int(m.body_jntnum[root])
        types = [
            self.mj.mjtJoint(int(m.jnt_type[j])).name[len("mjJNT_") :].lower()
            for j in range(adr, adr + num)
        ]
        names = [m.joint(j).name or f"joint{j}" for j in range(adr, adr + num)]
        joint = ",".join(names) if names else None
        if "free" in types:
            return "dynamic", joint
        return "kinematic", joint

    def world_velocity(self, b: int) -> tuple[np.ndarray, np.ndarray]:
        """(ω, v of the body-frame origin), both in world coordinates."""
        res = np.zeros(6)
        self.mj.mj_objectVelocity(self.m, self.d, self.mj.mjtObj.mjOBJ_XBODY, b, res, 0)
        return res[:3], res[3:]

    def run(self, include_visual: bool, skip_unsupported: bool):
        m, d = self.m, self.d
        per_root, fixed_geoms, grounds = self.classify_geoms(include_visual, skip_unsupported)
        bodies: list[LoadedBody] = []
        source_map: dict[int, int] = {}
        for g in fixed_geoms:
            v, f = self.geom_shape(g)
            name = self.geom_name(g)
            T = pose_matrix(np.array(d.geom_xmat[g]).reshape(3, 3), d.geom_xpos[g])
            bodies.append(
                make_body(
                    name,
                    "fixed",
                    [Surface(name, v, f)],
                    T,
                    kappa=self.kappa,
                    constitution=self.constitution,
                    mass=None,
                    links=(self.body_name(int(m.geom_bodyid[g])),),
                    friction=float(m.geom_friction[g, 0]),
                )
            )
        members: dict[int, list[int]] = {}
        for b in range(1, m.nbody):
            if int(m.body_weldid[b]) != 0:
                members.setdefault(int(m.body_weldid[b]), []).append(b)
        for root, group in members.items():
            kind, joint = self.group_kind(root)
            geoms = per_root.get(root, [])
            names = [self.body_name(b) for b in group]
            parts = []
            for b in group:
                mass, c, inertia = body_local_inertia(m, b)
                X = self.pose_in_root(b, root)
                parts.append(
                    (mass, transform_points(X, c[None])[0], X[:3, :3] @ inertia @ X[:3, :3].T)
                )
            mass = combine_inertias(parts)
            surfaces = []
            if not geoms and kind == "kinematic" and self.articulated and mass[0] > 0:
                # Articulated, a jointed group must carry its mass and its children's joints:
                # its inertia box, colliding with nothing (bridges/_inertia_proxy.py).
                surfaces = [inertia_box(f"{names[0]} (inertia box)", *mass)]
                self.notes.append(
                    f"body {names[0]!r} has mass {mass[0]:g} kg but no collision geometry: its "
                    "surface is its equivalent inertia box, which collides with nothing"
                )
            elif not geoms:
                note = (
                    f"body {names[0]!r} ({kind}) has no collision geometry: no body is made for it"
                )
                if kind == "dynamic":
                    raise LoaderError(
                        note + " (a free body needs a surface; include_visual=True may help)"
                    )
                self.notes.append(note)
                continue
            for g in geoms:
                v, f = self.geom_shape(g)
                X = self.pose_in_root(int(m.geom_bodyid[g]), root) @ self.geom_local_pose(g)
                surfaces.append(Surface(self.geom_name(g), transform_points(X, v), f))
            R = np.array(d.xmat[root]).reshape(3, 3)
            omega, vel = self.world_velocity(root)
            source_map[root] = len(bodies)
            bodies.append(
                make_body(
                    names[0],
                    kind,
                    surfaces,
                    pose_matrix(R, d.xpos[root]),
                    kappa=self.kappa,
                    constitution=self.constitution,
                    mass=mass if mass[0] > 0 else None,
                    velocity=velocity_matrix(R, omega, vel),
                    links=names,
                    joint=joint,
                    friction=float(max((m.geom_friction[g, 0] for g in geoms), default=0.0)),
                    notes=self.notes,
                )
            )
            if not geoms:  # an inertia box: no geom, so MuJoCo's filter pairs it with nothing
                bodies[-1].geoms, bodies[-1].geom_ranges, bodies[-1].friction = (), {}, None
        joints, compound = [], []
        for root, i in list(source_map.items()):
            parent = int(m.body_weldid[int(m.body_parentid[root])])
            bodies[i].parent = source_map.get(parent)
            adr, num = int(m.body_jntadr[root]), int(m.body_jntnum[root])
            # Articulated, a body on k > 1 joints hangs from its parent through k - 1 joint
            # frames, one joint each (bridges/_joint_frames.py).
            chain = [bodies[i].parent]
            if self.articulated and num > 1:
                frames = joint_frames(self, bodies[i], root)
                for frame in frames:
                    frame.parent = chain[-1]
                    chain.append(len(bodies))
                    bodies.append(frame)
                compound.append(bodies[i].name)
            chain.append(i)
            # (parent, child) of each joint: one link of the chain each, or (one joint, or a
            # kinematic body on several) parent and body.
            if len(chain) == 2:
                links = [(chain[0], i)] * num
            else:
                links = [(chain[n], chain[n + 1]) for n in range(num)]
            for j, (a, b) in zip(range(adr, adr + num), links, strict=True):
                kind = self.mj.mjtJoint(int(m.jnt_type[j])).name[len("mjJNT_") :].lower()
                kind = {"hinge": "revolute", "slide": "prismatic"}.get(kind, kind)
                axis = np.array(d.xaxis[j]) if kind in ("revolute", "prismatic") else None
                name = m.joint(j).name or f"joint{j}"
                joints.append(JointInfo(name, kind, a, b, np.array(d.xanchor[j]), axis, j))
        if compound:
            self.notes.append(compound_note(compound))
        return bodies, grounds, source_map, joints
