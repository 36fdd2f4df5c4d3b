"""URDF scenes as affine bodies, through Pinocchio.

One affine body per **Pinocchio joint** that carries collision geometry. Pinocchio treats URDF
``fixed`` joints as frames and merges every link fixed to a joint into that joint's body
(``model.inertias[j]`` is the merged inertia). abdsim does the same: the links of one
Pinocchio joint form one rigid group, their collision geometries are merged into one surface
(vertices in the joint frame), the body's pose is the joint frame's world placement
``oMi[j]`` and its mass properties are exactly ``model.inertias[j]`` (mass, lever =
centre of mass in the joint frame, inertia about the centre). The body is named after the
link that owns the group's first collision geometry; :attr:`LoadedBody.links` lists every
link of the group.

Kinds: the group on Pinocchio's universe joint (the root link of a fixed-base robot, and any
link fixed to it) is ``fixed``; the root of a floating-base robot (a free-flyer root joint) is
``dynamic``; every other group is ``kinematic`` and follows a joint trajectory through
:class:`abdsim.bridges.RobotDriver`.

Links joined by a joint never collide, nor SRDF ``disable_collisions`` pairs (``srdf=``), nor
links that touch a moving body in the loaded configuration (``bridges/_contact_rules.py``). A
group's inertia is checked after merging its fixed links; a degenerate one is bounded with a
note (``bridges/_inertia_repair.py``). A URDF without any ``<collision>`` uses its visuals.
"""

from __future__ import annotations

import os
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import NamedTuple

import numpy as np
import trimesh

from abdsim.bridges._bodies import (
    JointInfo,
    LoadedBody,
    LoaderError,
    LoadResult,
    Surface,
    check_file,
    closed_surface,
    make_body,
    primitive_surface,
    transform_points,
    velocity_matrix,
)
from abdsim.bridges._contact_rules import exclude_touching, urdf_rules
from abdsim.bridges._inertia_proxy import inertia_box
from abdsim.bridges._urdf_joint_frames import donor_keep, frame_donors, frame_mass, frames_note
from abdsim.bridges._urdf_visual import visual_only
from abdsim.bridges.articulated import check_articulation

_FREE_FLYER = "JointModelFreeFlyer"


def load_urdf(
    path: str | os.PathLike,
    package_dirs: Sequence[str | os.PathLike] | None = None,
    q: np.ndarray | None = None,
    kappa: float = 1e8,
    *,
    v: np.ndarray | None = None,
    floating_base: bool = False,
    constitution: str = "OrthoPotential",
    mass_density: float | None = None,
    open_mesh: str = "hull",
    srdf: str | os.PathLike | None = None,
    kinematic: bool = False,
) -> LoadResult:
    """Load a URDF robot as affine bodies placed at configuration ``q``: by default a dynamic
    articulation (every link group dynamic, joined by the URDF's joints).

    Args:
        path: the URDF file.
        package_dirs: folders that hold the packages ``package://NAME/...`` refers to (each
            folder contains ``NAME/``). Default: every ancestor of the URDF's folder, then
            ``ROS_PACKAGE_PATH``.
        q: configuration (``model.nq``), default ``pinocchio.neutral(model)``.
        kappa: shape stiffness κ of every body (Pa).
        v: joint velocity (``model.nv``) giving the bodies' initial ``velocity`` (dT/dt);
            zero by default.
        floating_base: add a free-flyer root joint (the robot's root becomes a dynamic body).
        constitution: ``"OrthoPotential"`` or ``"ARAP"``.
        mass_density: if given, a group with collision geometry but no URDF mass gets the mass
            of its surface at this density instead of raising.
        open_mesh: what to do with a mesh that is not a closed surface: ``"hull"`` (use its
            convex hull, with a warning) or ``"error"``.
        srdf: an SRDF file whose ``<disable_collisions>`` pairs never collide (links joined
            by a joint never do either).
        kinematic: False (default): the links are dynamic bodies and ``result.scene`` joins
            them by the URDF's joints with ``<dynamics damping friction>`` and ``<limit lower
            upper>`` (``bridges/articulated.py``); True: the links below the root are
            kinematic, scripted by :class:`abdsim.bridges.RobotDriver`.

    Returns:
        A :class:`LoadResult`; ``result.model`` is the ``pinocchio.Model``,
        ``result.collision_model`` the ``pinocchio.GeometryModel``.

    Raises:
        FileNotFoundError: the URDF or a collision mesh file does not exist.
        LoaderError (a ValueError): malformed XML, an element Pinocchio rejects, a link with a
            non-physical inertia, a group with geometry but no mass, an unsupported geometry or
            joint, a bad ``q``; articulated, a joint abdsim has no dynamic model of (planar,
            a floating joint below the root); the message names the link / joint / geometry.
    """
    import pinocchio as pin

    if open_mesh not in ("hull", "error"):
        raise ValueError(f"open_mesh must be 'hull' or 'error', got {open_mesh!r}")
    urdf = check_file(path, "URDF", (".urdf", ".xml"))
    dirs = _package_dirs(urdf, package_dirs)
    root = _parse_xml(urdf)
    _check_tree(root, urdf)
    link_mass = _check_inertials(root, urdf)
    collisions = _check_collision_meshes(root, urdf, dirs)
    notes: list[str] = []
    geometry_type = pin.GeometryType.COLLISION
    visual = visual_only(root, urdf)
    if visual is not None:  # bridges/_urdf_visual.py
        collisions, note = visual
        notes.append(note)
        geometry_type = pin.GeometryType.VISUAL

    kwargs = {"package_dirs": [str(d) for d in dirs]}
    if floating_base:
        kwargs["root_joint"] = pin.JointModelFreeFlyer()
    try:
        built = pin.buildModelsFromUrdf(str(urdf), geometry_types=[geometry_type], **kwargs)
    except (ValueError, RuntimeError, OSError) as e:
        raise LoaderError(f"Pinocchio could not load URDF {urdf}: {e}") from e
    model, collision_model = built[0], built[1]
    _check_all_collisions_loaded(collision_model, model, collisions, urdf)

    q = _configuration(pin, model, q, "q", model.nq)
    v = np.zeros(model.nv) if v is None else _configuration(pin, model, v, "v", model.nv)
    kin = joint_kinematics(pin, model, q, v)

    geoms_of: dict[int, list] = {}
    for g in collision_model.geometryObjects:
        geoms_of.setdefault(int(g.parentJoint), []).append(g)
    for j in range(1, model.njoints):
        if model.joints[j].shortname() == _FREE_FLYER and model.parents[j] != 0:
            raise LoaderError(
                f"joint {model.names[j]!r}: a floating joint below another joint is not "
                "supported (only a floating root)"
            )

    links_of: dict[int, list[str]] = {}  # one pass over the frames: linear in the links
    for f in model.frames:
        if f.type == pin.FrameType.BODY:
            links_of.setdefault(int(f.parentJoint), []).append(f.name)
    bodies: list[LoadedBody] = []
    body_of_joint: dict[int, int] = {}
    # Massless links without geometry that carry a joint (multi-axis hips): joint frames.
    donors = {} if kinematic else frame_donors(model, set(geoms_of))
    frames = {j: frame_mass(model, kin, j, d) for j, d in donors.items()}
    keep = donor_keep(donors)
    if donors:
        notes.append(frames_note(model, donors, links_of))
    for j in range(model.njoints):
        links = links_of.get(j, [])
        geoms = geoms_of.get(j, [])
        inertia = model.inertias[j]
        proxy = False
        if j in donors:
            proxy = True  # bridges/_urdf_joint_frames.py
        elif not geoms:
            if j > 0 and inertia.mass > 0 and not kinematic:
                # Articulated, the group must carry its mass and its children's joint: a body
                # whose surface is its inertia box, colliding with nothing (_inertia_proxy.py).
                proxy = True
                notes.append(
                    f"joint {model.names[j]!r} (links {links}) has mass {inertia.mass:g} kg but "
                    "no collision geometry: its body's surface is its equivalent inertia box, "
                    "which collides with nothing"
                )
            elif j > 0 and inertia.mass > 0:
                what = "dynamic" if _is_floating_root(model, j) else "kinematic"
                note = (
                    f"joint {model.names[j]!r} (links {links}) has mass {inertia.mass:g} kg but "
                    f"no collision geometry: no {what} body is made for it"
                )
                if what == "dynamic":
                    raise LoaderError(f"URDF {urdf.name}: {note}")
                notes.append(note)
                continue
            else:
                continue
        if proxy:
            name = links[0] if links else model.names[j]
            if j in frames:
                surfaces = [inertia_box(f"{name} (joint frame)", *frames[j])]
            else:
                surfaces = [
                    inertia_box(
                        f"{name} (inertia box)",
                        inertia.mass,
                        np.array(inertia.lever),
                        np.array(inertia.inertia),
                    )
                ]
        else:
            name = model.frames[int(geoms[0].parentFrame)].name
            surfaces = [_geometry_surface(pin, g, model, open_mesh, notes) for g in geoms]
        links = [name] + [n for n in links if n != name]
        if j == 0:
            # The fixed root: Pinocchio's universe inertia when the URDF gives one (its mass
            # plays no role for a fixed body), else the surface's mass.
            kind = "fixed"
            mass = _joint_mass(model, 0, links, link_mass, mass_density or 1e3)
        else:
            kind = "dynamic" if _is_floating_root(model, j) else "kinematic"
            if model.inertias[j].mass <= 0 and mass_density is None and j not in donors:
                # A moving group without mass is repaired, never refused: its surface's mass.
                missing = [n for n in links if link_mass.get(n) is None]
                notes.append(
                    f"joint {model.names[j]!r} (links {links}) has collision geometry but no "
                    f"mass (links without <inertial>: {missing}): using its geometry's mass at "
                    "1000 kg/m^3 (pass mass_density= to choose the density)"
                )
            if j in frames:
                mass = frames[j]
            else:
                mass = _joint_mass(model, j, links, link_mass, mass_density or 1e3)
            if j in keep and mass is not None:  # the share its joint frames carry
                mass = (keep[j] * mass[0], mass[1], keep[j] * mass[2])
        oMi, vj = kin.oMi[j], kin.v[j]
        R = np.array(oMi.rotation)
        velocity = velocity_matrix(R, R @ vj.angular, R @ vj.linear)
        body = make_body(
            name,
            kind,
            surfaces,
            np.array(oMi.homogeneous),
            kappa=kappa,
            constitution=constitution,
            mass=mass,
            velocity=velocity,
            links=links,
            joint=model.names[j] if j > 0 else None,
            mass_density=mass_density or 1e3,
            notes=notes,
        )
        body.parent = _parent_body(model, j, body_of_joint)
        if proxy:
            body.geoms, body.geom_ranges = (), {}
        parent_joint = int(model.parents[j])
        if not kinematic and parent_joint > 0 and parent_joint not in body_of_joint:
            raise LoaderError(
                f"URDF {urdf.name}: joint {model.names[j]!r} hangs from joint "
                f"{model.names[parent_joint]!r}, whose links have neither mass nor collision "
                "geometry, and no link below it has mass to lend a joint frame "
                "(bridges/_urdf_joint_frames.py): no body can carry that joint; load with "
                "kinematic=True to script it"
            )
        body_of_joint[j] = len(bodies)
        bodies.append(body)
    if not bodies:
        raise LoaderError(f"URDF {urdf} has no link with collision geometry: nothing to simulate")
    if not kinematic:  # before the touching pairs: every link now moves by the dynamics
        bodies = [replace(b, kind="dynamic") if b.kind == "kinematic" else b for b in bodies]
    rules = _contact_rules(bodies, srdf)
    for i, body in enumerate(bodies):
        if not body.geoms:  # an inertia box (_inertia_proxy.py) collides with nothing
            rules.excluded.update((min(i, k), max(i, k)) for k in range(len(bodies)) if k != i)
    exclude_touching(bodies, rules, notes)  # bridges/_contact_rules.py
    for note in notes:
        warnings.warn(note, stacklevel=2)
    result = LoadResult(
        source=urdf,
        format="urdf",
        bodies=bodies,
        joints=_joints(model, kin, body_of_joint, bodies),
        model=model,
        collision_model=collision_model,
        q=q,
        source_map=body_of_joint,
        notes=notes,
        contact_rules=rules,
        articulated=not kinematic,
    )
    if not kinematic:
        check_articulation(result)  # a clear error now rather than at result.scene
    return result


# ---------------------------------------------------------------------------------------------
# Input checks
# ---------------------------------------------------------------------------------------------
def _package_dirs(urdf: Path, package_dirs: Sequence[str | os.PathLike] | None) -> list[Path]:
    if package_dirs is not None:
        if isinstance(package_dirs, (str, os.PathLike)):
            package_dirs = [package_dirs]
        dirs = [Path(d).expanduser() for d in package_dirs]
    else:
        dirs = list(urdf.parent.parents) + [urdf.parent]
    for d in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if d:
            dirs.append(Path(d))
    return dirs


def _parse_xml(urdf: Path) -> ET.Element:
    try:
        root = ET.parse(urdf).getroot()
    except ET.ParseError as e:
        raise LoaderError(f"malformed URDF {urdf}: {e}") from e
    if root.tag != "robot":
        raise LoaderError(f"URDF {urdf}: root element is <{root.tag}>, expected <robot>")
    if root.find("link") is None:
        raise LoaderError(f"URDF {urdf} has no <link>")
    return root


_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


def _vector_attr(elem: ET.Element | None, key: str, where: str) -> np.ndarray | None:
    """3 finite numbers in attribute ``key`` of ``elem`` (None if absent)."""
    raw = None if elem is None else elem.get(key)
    if raw is None:
        return None
    try:
        vec = np.array([float(x) for x in raw.split()])
    except ValueError:
        vec = np.array([])
    if vec.shape != (3,) or not np.isfinite(vec).all():
        raise LoaderError(f"{where}: <{elem.tag} {key}={raw!r}> must be 3 finite numbers")
    return vec


def _check_tree(root: ET.Element, urdf: Path) -> None:
    """Links and joints form one tree, every joint is complete: errors name the element.

    Pinocchio (urdfdom) reports any of these as "does not contain a valid URDF model".
    """
    names: set[str] = set()
    # direct children only: <transmission> and <gazebo> blocks also hold <joint>/<link> tags
    for k, link in enumerate(root.findall("link")):
        name = link.get("name")
        if not name:
            raise LoaderError(f"URDF {urdf.name}: <link> number {k} has no name")
        if name in names:
            raise LoaderError(f"URDF {urdf.name}: two links are named {name!r}")
        names.add(name)
    parent_of: dict[str, str] = {}
    children: dict[str, list[str]] = {}
    joint_names: set[str] = set()
    for k, joint in enumerate(root.findall("joint")):
        jname = joint.get("name")
        if not jname:
            raise LoaderError(f"URDF {urdf.name}: <joint> number {k} has no name")
        where = f"URDF {urdf.name}, joint {jname!r}"
        if jname in joint_names:
            raise LoaderError(f"URDF {urdf.name}: two joints are named {jname!r}")
        joint_names.add(jname)
        kind = joint.get("type")
        if kind not in _JOINT_TYPES:
            raise LoaderError(f"{where}: type {kind!r} is not one of {list(_JOINT_TYPES)}")
        ends = {}
        for end in ("parent", "child"):
            elem = joint.find(end)
            link = elem.get("link") if elem is not None else None
            if not link:
                raise LoaderError(f"{where}: no <{end} link=...>")
            if link not in names:
                raise LoaderError(f"{where}: {end} link {link!r} does not exist")
            ends[end] = link
        if ends["child"] in parent_of:
            raise LoaderError(
                f"{where}: link {ends['child']!r} is already the child of link "
                f"{parent_of[ends['child']]!r} (a link has one parent joint)"
            )
        parent_of[ends["child"]] = ends["parent"]
        children.setdefault(ends["parent"], []).append(ends["child"])
        origin = joint.find("origin")
        _vector_attr(origin, "xyz", where)
        _vector_attr(origin, "rpy", where)
        axis = _vector_attr(joint.find("axis"), "xyz", where)
        if axis is not None and kind != "fixed" and not np.linalg.norm(axis) > 0:
            raise LoaderError(f"{where}: <axis xyz> is zero")
        if kind in ("revolute", "prismatic") and joint.find("limit") is None:
            raise LoaderError(f"{where}: a {kind} joint needs a <limit>")
    roots = [n for n in names if n not in parent_of]
    if len(roots) != 1:
        raise LoaderError(
            f"URDF {urdf.name}: the links form {'no tree (a cycle)' if not roots else 'a forest'}"
            f"; root links (no parent joint): {sorted(roots)[:10]}"
        )
    reached, stack = {roots[0]}, [roots[0]]
    while stack:  # iterative: a 2,000-link chain is deeper than Python's recursion limit
        for child in children.get(stack.pop(), []):
            if child not in reached:
                reached.add(child)
                stack.append(child)
    if len(reached) != len(names):
        cut = sorted(names - reached)[:10]
        raise LoaderError(f"URDF {urdf.name}: links {cut} are in a cycle, not below the root")


def _float_attr(elem: ET.Element, key: str, where: str) -> float:
    raw = elem.get(key)
    if raw is None:
        raise LoaderError(f"{where}: <{elem.tag}> has no {key!r} attribute")
    try:
        return float(raw)
    except ValueError as e:
        raise LoaderError(f"{where}: <{elem.tag} {key}={raw!r}> is not a number") from e


def _check_inertials(root: ET.Element, urdf: Path) -> dict[str, float | None]:
    """Each link's URDF mass (None: no <inertial>); non-physical inertials raise."""
    masses: dict[str, float | None] = {}
    for link in root.iter("link"):
        name = link.get("name", "?")
        inertial = link.find("inertial")
        if inertial is None:
            masses[name] = None
            continue
        where = f"URDF {urdf.name}, link {name!r}"
        mass_elem = inertial.find("mass")
        if mass_elem is None:
            raise LoaderError(f"{where}: <inertial> has no <mass>")
        mass = _float_attr(mass_elem, "value", where)
        if not np.isfinite(mass) or mass < 0:
            raise LoaderError(f"{where}: mass must be finite and >= 0, got {mass}")
        masses[name] = mass
        inertia_elem = inertial.find("inertia")
        if mass == 0:
            continue
        if inertia_elem is None:
            raise LoaderError(f"{where}: <inertial> has a mass but no <inertia>")
        c = {
            k: _float_attr(inertia_elem, k, where)
            for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        }
        tensor = np.array(
            [
                [c["ixx"], c["ixy"], c["ixz"]],
                [c["ixy"], c["iyy"], c["iyz"]],
                [c["ixz"], c["iyz"], c["izz"]],
            ]
        )
        if not np.isfinite(tensor).all():
            raise LoaderError(f"{where}: inertia has non-finite entries")
        # A link's own inertia may be degenerate (a point mass on a sensor frame): only the
        # rigid group it joins must be physical, checked (and bounded) in make_body.
    return masses


def _resolve_mesh(filename: str, urdf: Path, dirs: Sequence[Path]) -> Path | None:
    if filename.startswith("package://"):
        # "package:///a/b" (an empty package name, talos_full_v2) is "a/b" under a package dir.
        rest = filename[len("package://") :].lstrip("/")
        for d in dirs:
            candidate = d / rest
            if candidate.is_file():
                return candidate
        return None
    if filename.startswith("file://"):
        filename = filename[len("file://") :]
    p = Path(filename)
    if not p.is_absolute():
        p = urdf.parent / p
    return p if p.is_file() else None


def _check_collision_meshes(root: ET.Element, urdf: Path, dirs: Sequence[Path]) -> dict[str, int]:
    """Every collision element is a supported shape with an existing mesh; counts per link."""
    counts: dict[str, int] = {}
    known = {"box", "sphere", "cylinder", "mesh"}  # what urdfdom parses
    for link in root.iter("link"):
        name = link.get("name", "?")
        for collision in link.findall("collision"):
            geometry = collision.find("geometry")
            shapes = list(geometry) if geometry is not None else []
            if not shapes:
                raise LoaderError(f"URDF {urdf.name}, link {name!r}: <collision> has no geometry")
            tag = shapes[0].tag
            if tag not in known:
                raise LoaderError(
                    f"URDF {urdf.name}, link {name!r}: unsupported collision geometry <{tag}> "
                    f"(supported: {sorted(known)})"
                )
            counts[name] = counts.get(name, 0) + 1
            if tag == "mesh":
                filename = shapes[0].get("filename", "")
                if _resolve_mesh(filename, urdf, dirs) is None:
                    raise FileNotFoundError(
                        f"URDF {urdf.name}, link {name!r}: collision mesh {filename!r} not found "
                        f"(searched package dirs {[str(d) for d in dirs]})"
                    )
    return counts


def _check_all_collisions_loaded(collision_model, model, expected: dict[str, int], urdf) -> None:
    """urdfdom skips a collision element it cannot parse (printing to stderr): refuse that."""
    loaded: dict[str, int] = {}
    for g in collision_model.geometryObjects:
        link = model.frames[int(g.parentFrame)].name
        loaded[link] = loaded.get(link, 0) + 1
    for link, n in expected.items():
        if loaded.get(link, 0) != n:
            raise LoaderError(
                f"URDF {urdf.name}, link {link!r}: {n} <collision> element(s) but Pinocchio "
                f"loaded {loaded.get(link, 0)} (an element it could not parse)"
            )


def _configuration(pin, model, value, what: str, n: int) -> np.ndarray:
    if value is None:
        return pin.neutral(model)
    arr = np.asarray(value, dtype=np.float64).reshape(-1)
    if arr.shape != (n,):
        raise LoaderError(f"{what} must have {n} entries for this robot, got {arr.size}")
    if not np.isfinite(arr).all():
        raise LoaderError(f"{what} contains NaN or infinite values")
    return arr


# ---------------------------------------------------------------------------------------------
# Kinematics
# ---------------------------------------------------------------------------------------------
class Kinematics(NamedTuple):
    """Per joint: world placement oMi (pinocchio.SE3), spatial velocity in the joint frame
    (pinocchio.Motion) and motion subspace S (6, nv_j)."""

    oMi: list
    v: list
    S: list


def joint_kinematics(pin, model, q: np.ndarray, v: np.ndarray) -> Kinematics:
    """Pinocchio's forward kinematics (oMi, v, S) without a ``pinocchio.Data``.

    ``model.createData()`` allocates dense buffers for every algorithm (nv x nv matrices and
    larger): a 400-joint chain took 4 GB and 2,000 joints ran out of memory. Placements and
    velocities need only one pass down the tree (parents precede children):
    oMi = oMi[parent] · jointPlacement · M_j(q), v = v_j(q, v) + (liMi)⁻¹ · v[parent].
    """
    n = model.njoints
    oMi, vel, S = [pin.SE3.Identity()] * n, [pin.Motion.Zero()] * n, [np.zeros((6, 0))] * n
    for j in range(1, n):
        joint = model.joints[j]
        jdata = joint.createData()
        joint.calc(jdata, q, v)
        liMi = model.jointPlacements[j] * jdata.M
        parent = model.parents[j]
        oMi[j] = oMi[parent] * liMi
        vj = pin.Motion(jdata.v)
        vel[j] = vj + liMi.actInv(vel[parent]) if parent > 0 else vj
        S[j] = np.array(jdata.S)
    return Kinematics(oMi, vel, S)


# ---------------------------------------------------------------------------------------------
# Bodies
# ---------------------------------------------------------------------------------------------
def _is_floating_root(model, j: int) -> bool:
    return model.parents[j] == 0 and model.joints[j].shortname() == _FREE_FLYER


def _parent_body(model, j: int, body_of_joint: dict[int, int]) -> int | None:
    k = model.parents[j] if j > 0 else None
    while k is not None:
        if k in body_of_joint:
            return body_of_joint[k]
        k = model.parents[k] if k > 0 else None
    return None


def _joints(model, kin: Kinematics, body_of_joint: dict[int, int], bodies) -> list[JointInfo]:
    out = []
    for j, i in body_of_joint.items():
        if j == 0:
            continue
        joint, R = model.joints[j], np.array(kin.oMi[j].rotation)
        kind, axis = "other", None
        if joint.shortname() == _FREE_FLYER:
            kind = "free"
        elif joint.shortname() == "JointModelSpherical":
            kind = "ball"
        elif joint.nv == 1:
            S = kin.S[j].reshape(-1)
            if np.linalg.norm(S[3:]) > 0:
                kind, axis = "revolute", R @ S[3:]
            else:
                kind, axis = "prismatic", R @ S[:3]
            axis = axis / np.linalg.norm(axis)
        anchor = np.array(kin.oMi[j].translation)
        out.append(JointInfo(model.names[j], kind, bodies[i].parent, i, anchor, axis, j))
    return out


def _joint_mass(model, j, links, link_mass, mass_density):
    inertia = model.inertias[j]
    if inertia.mass > 0:
        return float(inertia.mass), np.array(inertia.lever), np.array(inertia.inertia)
    if mass_density is not None:
        return None
    missing = [n for n in links if link_mass.get(n) is None]
    hint = f"links without <inertial>: {missing}" if missing else "every link has zero mass"
    raise LoaderError(
        f"joint {model.names[j]!r} (links {links}) has collision geometry but no mass ({hint}); "
        "add an <inertial> or pass mass_density= to use the geometry's mass"
    )


def _geometry_surface(pin, g, model, open_mesh: str, notes: list[str]) -> Surface:
    """The geometry object's closed surface in its parent joint's frame."""
    import coal

    shape = g.geometry
    link = model.frames[int(g.parentFrame)].name
    label = f"{g.name} (link {link!r})"
    if isinstance(shape, coal.Box):
        v, f = primitive_surface("box", np.array(shape.halfSide), label)
    elif isinstance(shape, coal.Sphere):
        v, f = primitive_surface("sphere", [shape.radius], label)
    elif isinstance(shape, coal.Capsule):
        v, f = primitive_surface("capsule", [shape.radius, shape.halfLength], label)
    elif isinstance(shape, coal.Cylinder):
        v, f = primitive_surface("cylinder", [shape.radius, shape.halfLength], label)
    elif g.meshPath and Path(g.meshPath).is_file() and isinstance(shape, coal.CollisionGeometry):
        try:
            mesh = trimesh.load(g.meshPath, force="mesh")
        except Exception as e:  # trimesh raises many types on bad files
            raise LoaderError(f"geometry {label}: cannot read mesh {g.meshPath}: {e}") from e
        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            raise LoaderError(f"geometry {label}: mesh {g.meshPath} has no triangles")
        v = np.asarray(mesh.vertices, dtype=np.float64) * np.asarray(g.meshScale)
        f = np.asarray(mesh.faces)
        if np.linalg.det(np.diag(np.asarray(g.meshScale, dtype=float))) < 0:
            f = f[:, ::-1]  # a mirroring scale flips the winding
        v, f = closed_surface(label, v, f, open_mesh, notes)
    else:
        raise LoaderError(
            f"geometry {label}: unsupported collision shape {type(shape).__name__} "
            f"(mesh path {g.meshPath!r})"
        )
    return Surface(g.name, transform_points(np.array(g.placement.homogeneous), v), f)


def _contact_rules(bodies, srdf):
    """Adjacent links and the SRDF's pairs never collide (bridges/_contact_rules.py)."""
    if srdf is None:
        return urdf_rules(bodies)
    path = check_file(srdf, "SRDF", (".srdf", ".xml"))
    try:
        return urdf_rules(bodies, path)
    except ValueError as e:
        raise LoaderError(str(e)) from e
