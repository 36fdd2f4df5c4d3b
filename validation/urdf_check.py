"""``abdsim validate robot.urdf``: mass properties of every loaded link group against
Pinocchio's ``model.inertias`` and MuJoCo's compiled URDF.

Part of every URDF robot's report (``robot_validation`` compares its motion); the whole report
of a robot without moving joints. The check is that each body carries exactly the robot's
inertials. MuJoCo does not resolve ``package://`` URIs and cannot read COLLADA visuals, so it gets a
copy of the URDF with packages resolved and visual elements removed (they carry no mass).
"""

from __future__ import annotations

import re
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np


def mujoco_ready_urdf(urdf: Path, package_dirs: list[Path], out_dir: Path) -> Path:
    """A copy of ``urdf`` that MuJoCo can load: package:// resolved, no <visual>."""
    tree = ET.parse(urdf)
    root = tree.getroot()
    for link in root.iter("link"):
        for visual in list(link.findall("visual")):
            link.remove(visual)
    for mesh in root.iter("mesh"):
        name = mesh.get("filename", "")
        match = re.match(r"package://([^/]+)/(.*)", name)
        if match:
            for base in package_dirs:
                candidate = Path(base) / match.group(1) / match.group(2)
                if candidate.is_file():
                    mesh.set("filename", str(candidate.resolve()))
                    break
        elif name and not Path(name).is_absolute():
            mesh.set("filename", str((urdf.parent / name).resolve()))
    path = out_dir / f"{urdf.stem}.mujoco.urdf"
    tree.write(path)
    return path


def urdf_inertia_comparisons(
    urdf: Path, out_dir: Path, perturb_mass: dict[str, float] | None = None
):
    """([(reference, names, abdsim rigid bodies, reference rigid bodies)], notes);
    ``perturb_mass`` {link: factor} scales links in abdsim only (a wrong model)."""
    import mujoco

    import abdsim
    from abdsim.bridges import load_urdf
    from abdsim.bridges.urdf import _package_dirs

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = load_urdf(urdf)
    if perturb_mass:
        from abdsim.validation.robot_setup import perturb_masses

        perturb_masses(loaded, perturb_mass)
    model = loaded.model
    joint_of_body = {b: j for j, b in loaded.source_map.items()}
    names, abd, pin_ref, bodies = [], [], [], []
    for i, body in enumerate(loaded.bodies):
        j = joint_of_body.get(i)
        if j is None or j == 0:
            continue  # the world-attached base has no Pinocchio joint inertia of its own
        inertia = model.inertias[j]
        if inertia.mass <= 0:
            continue
        rb = abdsim.to_rigid_body(body.geometry)
        names.append(body.name)
        bodies.append(body)
        abd.append((rb.mass, rb.mass_center, rb.inertia))
        pin_ref.append((inertia.mass, np.array(inertia.lever), np.array(inertia.inertia)))
    if not names:
        raise ValueError(f"{urdf}: no moving link with mass to compare")
    comparisons = [("Pinocchio", names, abd, pin_ref)]
    notes = [
        "mass properties of every moving link group are compared with Pinocchio's and "
        "MuJoCo's (the fixed root's play no role)"
    ]
    try:
        mj_path = mujoco_ready_urdf(urdf, _package_dirs(urdf, None), out_dir)
        notes.append(
            f"{mj_path.name} (beside this report) is the URDF as MuJoCo compiled it: "
            "package:// mesh paths resolved to files, which MuJoCo's URDF compiler needs"
        )
        mj = mujoco.MjModel.from_xml_path(str(mj_path))
    except Exception as err:  # noqa: BLE001 - reported, Pinocchio's check still stands
        notes.append(f"MuJoCo rejected the URDF, so it is not compared: {err}")
        return comparisons, notes
    mj_rows, keep = [], []
    for k, body in enumerate(bodies):
        b = mujoco.mj_name2id(
            mj, mujoco.mjtObj.mjOBJ_BODY, body.links[0] if body.links else body.name
        )
        if b < 0:
            notes.append(f"MuJoCo merged link {body.name!r} away (fusestatic): not compared")
            continue
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, mj.body_iquat[b])
        R = R.reshape(3, 3)
        mj_rows.append(
            (float(mj.body_mass[b]), mj.body_ipos[b].copy(), R @ np.diag(mj.body_inertia[b]) @ R.T)
        )
        keep.append(k)
    comparisons.append(("MuJoCo", [names[k] for k in keep], [abd[k] for k in keep], mj_rows))
    return comparisons, notes
