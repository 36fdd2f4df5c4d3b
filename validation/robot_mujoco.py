"""The MuJoCo twin of a URDF robot loaded in abdsim, for ``abdsim validate robot.urdf``.

MuJoCo compiles the MuJoCo-ready URDF (``urdf_check.mujoco_ready_urdf``: package:// paths
resolved, visuals dropped). Its joints then get abdsim's joint physics (damping, armature,
friction loss, limits, as ``build_articulated_scene`` set them), so both simulate the same
model whatever the URDF reader of either side takes from ``<dynamics>``/``<limit>`` (abdsim's
limits are relative to the loaded configuration, MuJoCo's absolute: ``q_load + limits``). A
floating robot gets a free joint on its root body, a z-up floor, and only robot–floor
contacts (the robot's own links do not collide: abdsim excludes adjacent links and nothing
else touches in a stance). Joint coordinates are mapped by name: MuJoCo names its joints
after the URDF's.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class JointMap:
    """Where each abdsim joint (scene order) sits in Pinocchio's and MuJoCo's vectors.

    ``pin_q``/``pin_nq``: Pinocchio's ``idx_q``/``nq`` (nq = 2 for a continuous joint, as
    (cos, sin)); ``pin_v``: ``idx_v``; ``mj_q``/``mj_v``: MuJoCo's ``jnt_qposadr``/``jnt_dofadr``.
    """

    names: list[str]
    pin_q: np.ndarray
    pin_nq: np.ndarray
    pin_v: np.ndarray
    mj_q: np.ndarray
    mj_v: np.ndarray

    def pin_positions(self, q: np.ndarray) -> np.ndarray:
        """Joint coordinates (one per joint) of a Pinocchio configuration."""
        out = np.empty(len(self.names))
        for k, (a, n) in enumerate(zip(self.pin_q, self.pin_nq, strict=True)):
            out[k] = np.arctan2(q[a + 1], q[a]) if n == 2 else q[a]
        return out


def joint_map(scene, pin_model, mj_model=None) -> JointMap:
    """Indices of the scene's 1-dof joints in Pinocchio's (and MuJoCo's) vectors.

    Raises:
        ValueError: a scene joint that is not 1-dof, or that a peer model lacks (named).
    """
    import mujoco

    names, pq, pn, pv, mq, mv = [], [], [], [], [], []
    for j in scene.joints:
        if j.kind not in ("revolute", "prismatic"):
            raise ValueError(f"joint {j.name!r}: {j.kind} joints are not compared (1-dof only)")
        if not pin_model.existJointName(j.name):
            raise ValueError(f"joint {j.name!r} is not a joint of the Pinocchio model")
        jid = pin_model.getJointId(j.name)
        names.append(j.name)
        pq.append(pin_model.idx_qs[jid])
        pn.append(pin_model.nqs[jid])
        pv.append(pin_model.idx_vs[jid])
        if mj_model is not None:
            k = mujoco.mj_name2id(mj_model, mujoco.mjtObj.mjOBJ_JOINT, j.name)
            if k < 0:
                raise ValueError(f"joint {j.name!r} is not a joint of MuJoCo's model")
            mq.append(mj_model.jnt_qposadr[k])
            mv.append(mj_model.jnt_dofadr[k])
    ints = [np.asarray(x, dtype=int) for x in (pq, pn, pv, mq, mv)]
    return JointMap(names, *ints)


def mujoco_robot(urdf: Path, out_dir: Path, scene, q_load: dict[str, float], **options):
    """(MjModel, path of the MuJoCo-ready URDF, notes): ``mujoco_robot_spec`` compiled.

    Raises:
        ValueError: MuJoCo rejects or cannot compile the file (its message).
    """

    spec, path, notes = mujoco_robot_spec(urdf, out_dir, scene, q_load, **options)
    try:
        return spec.compile(), path, notes
    except ValueError as err:
        raise ValueError(f"MuJoCo could not compile {urdf}: {err}") from err


def mujoco_robot_spec(
    urdf: Path,
    out_dir: Path,
    scene,
    q_load: dict[str, float],
    *,
    floating: bool = False,
    friction: float = 1.0,
    actuators: list[tuple[str, float, float]] = (),
    floor: bool = True,
):
    """(MjSpec, path of the MuJoCo-ready URDF, notes) of ``urdf`` with ``scene``'s joint
    physics. MuJoCo turns a URDF ``<mimic>`` into a joint equality constraint, which abdsim's
    articulation (and Pinocchio's model) do not have: it is removed, with a note.

    Args:
        urdf: the robot file.
        out_dir: where the MuJoCo-ready URDF is written.
        scene: the abdsim scene (``build_articulated_scene``) whose joints set MuJoCo's.
        q_load: each joint's coordinate at load (abdsim's zero), for limits and springs.
        floating: add a free joint on the root body, a floor at z = 0 and robot–floor
            contact only; otherwise contact is disabled (abdsim compares without contact).
        friction: sliding friction of every geom (MuJoCo takes the max of a pair).
        actuators: ``(joint name, kp, kv)`` position actuators, in ``world.ctrl`` order.
        floor: with ``floating``, add the floor (False: robots attached to a spec that has
            one).

    Raises:
        ValueError: MuJoCo rejects the file (its message).
    """
    import mujoco

    from abdsim.bridges.urdf import _package_dirs
    from abdsim.validation.urdf_check import mujoco_ready_urdf

    path = mujoco_ready_urdf(urdf, _package_dirs(urdf, None), out_dir)
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as err:
        raise ValueError(f"MuJoCo rejected {urdf}: {err}") from err
    notes = []
    for eq in list(spec.equalities):
        notes.append(
            f"MuJoCo's equality between {eq.name1!r} and {eq.name2!r} (from a URDF <mimic>) is "
            "removed: abdsim's articulation has no such coupling"
        )
        spec.delete(eq)
    by_name = {j.name: j for j in scene.joints}
    for joint in spec.joints:
        ours = by_name.get(joint.name)
        if ours is None:
            continue
        # MuJoCo 4 keeps damping and stiffness as polynomials: the linear term is ours.
        joint.damping = [ours.damping, 0.0, 0.0]
        joint.stiffness = [ours.stiffness, 0.0, 0.0]
        joint.springref = q_load[ours.name] + ours.ref
        joint.armature = ours.armature
        joint.frictionloss = ours.frictionloss
        if ours.limits is None:
            joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE
        else:
            joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            joint.range = [q_load[ours.name] + x for x in ours.limits]
    if floating:
        root = spec.worldbody.first_body()
        root.add_freejoint()
        for geom in spec.geoms:
            geom.contype, geom.conaffinity = 1, 0  # robot–robot pairs never collide
            geom.friction[0] = friction
        if floor:
            add_floor(spec, friction)
    else:
        spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    for name, kp, kv in actuators:
        act = spec.add_actuator(name=f"{name}_position", target=name)
        act.trntype = mujoco.mjtTrn.mjTRN_JOINT
        act.set_to_position(kp=kp, kv=kv)
    return spec, path, notes


def add_floor(spec, friction: float) -> None:
    """A z-up plane at z = 0 that touches every robot geom (contype 1) and nothing else."""
    import mujoco

    floor = spec.worldbody.add_geom(
        name="abdsim_floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0]
    )
    floor.contype, floor.conaffinity = 0, 1
    floor.friction[0] = friction
