"""Articulations from a Pinocchio model: every joint body of a fixed-base tree becomes an
affine body with the body's exact mass properties, joined to its parent by the same joint.

Used by the joint tests and benchmarks (UR5, Panda from example-robot-data) to run the same
robot in abdsim, Pinocchio and MuJoCo. Each body's geometry is a proxy box spanning the joint
origin and the centre of mass (no collision meshes: build the scene with ``contact=False``
or give bodies real geometry); its rest frame is Pinocchio's joint frame, so ``world.q[b][:3]``
is the joint origin ``data.oMi[i].translation``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

import abdsim

_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


def joint_axis(joint: Any) -> tuple[str, np.ndarray]:
    """("revolute" | "prismatic", local unit axis) of a Pinocchio 1-dof joint model."""
    name = joint.shortname()
    if name in ("JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"):
        axis = np.asarray(joint.extract().axis, dtype=np.float64)
    elif name[-1] in _AXES and name[:-1] in ("JointModelR", "JointModelP"):
        axis = np.asarray(_AXES[name[-1]])
    else:
        raise ValueError(f"unsupported Pinocchio joint {name} (revolute and prismatic only)")
    return ("revolute" if name.startswith("JointModelR") else "prismatic"), axis


def articulation_from_pinocchio(
    model: Any, q0: np.ndarray, scene: abdsim.Scene, kappa: float = 1e10
) -> dict[int, abdsim.BodyHandle]:
    """Adds the tree of `model` at configuration q0 to `scene` (bodies and joints, joint
    names as in the model); returns the body handle of each joint index (1..njoints-1).

    Joint coordinates in abdsim are relative to q0 (θ_abdsim = q − q0 for each 1-dof joint).
    """
    import pinocchio as pin

    data = model.createData()
    pin.forwardKinematics(model, data, np.asarray(q0, dtype=np.float64))
    bodies: dict[int, abdsim.BodyHandle | None] = {0: None}
    for i in range(1, model.njoints):
        kind, axis = joint_axis(model.joints[i])
        inertia = model.inertias[i]
        if not inertia.mass > 0.0:
            raise ValueError(f"joint {model.names[i]!r}: its body has no mass")
        box = abdsim.geometry.box(np.abs(inertia.lever) + 0.04)
        sc = abdsim.geometry.triangle_mesh(box.positions + inertia.lever / 2, box.triangles)
        abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=kappa)
        abdsim.assign_rigid_body(sc, inertia.mass, inertia.lever, inertia.inertia)
        sc.transforms = data.oMi[i].homogeneous[None]
        handle = scene.add(sc)
        scene.add_joint(
            kind,
            bodies[model.parents[i]],
            handle,
            anchor=data.oMi[i].translation,
            axis=data.oMi[i].rotation @ axis,
            name=model.names[i],
        )
        bodies[i] = handle
    return {i: h for i, h in bodies.items() if h is not None}
