"""Joint coordinates between abdsim and the source model: MuJoCo ``qpos``/``qvel`` (MJCF) or
Pinocchio ``q``/``v`` (URDF), as plain arrays.

abdsim's joint coordinates (``world.joint_positions()``/``joint_velocities()``, joint order
``result.joint_names``) are relative to the loaded configuration ``result.q``:

* hinge / revolute and slide / prismatic: ``q = q_load + θ`` (Pinocchio's continuous joints
  store ``(cos φ, sin φ)`` with ``φ = atan2(q_load) + θ``); velocities are the same numbers.
* ball / spherical: abdsim's quaternion ``Q`` is the child's rotation relative to load, in the
  child's frame, so the source's quaternion is ``q_load ⊗ Q`` (MuJoCo w-first, Pinocchio
  x-first); the velocity (relative ω in the child's frame) is the same in all three.
* free bodies (MuJoCo ``free`` joints, Pinocchio's free-flyer root) are not abdsim joints:
  their ``qpos`` is the body frame's position and quaternion, read from the body's state;
  MuJoCo's ``qvel`` is (v in the world, ω in the body frame), Pinocchio's ``v`` is both in
  the body frame.

Entries of joints that are not in the scene (on bodies without geometry) keep their loaded
values. A body on several MJCF joints hangs from joint frames (``bridges/_joint_frames.py``):
each of its joints is still one abdsim joint, and ``set_world_state`` places the frames too.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from abdsim.sim import pose as pose_math

#: (nq, nv) of an abdsim joint coordinate per kind (free joints are bodies' states).
_SIZES = {"revolute": (1, 1), "prismatic": (1, 1), "ball": (4, 3)}


def _conj(q: np.ndarray) -> np.ndarray:
    return np.array([q[0], -q[1], -q[2], -q[3]])


class _Slot:
    """Where one joint lives: abdsim (offset in positions / velocities) and source (qpos
    address, dof address), kind, loaded source coordinates."""

    def __init__(self, kind: str, body: int, aq: int, av: int, sq: int, sv: int, nq: int):
        self.kind, self.body = kind, body
        self.aq, self.av, self.sq, self.sv, self.nq = aq, av, sq, sv, nq


def _source_slots(result: Any) -> tuple[list[_Slot], int, int]:
    """Slots of every joint of ``result.joints`` (abdsim order), and the source's nq, nv."""
    m = result.model
    slots, aq, av = [], 0, 0
    for j in result.joints:
        if result.format == "mjcf":
            jid = j.source_id if j.source_id is not None else m.joint(j.name).id
            sq, sv = int(m.jnt_qposadr[jid]), int(m.jnt_dofadr[jid])
            nq = {"free": 7, "ball": 4}.get(j.type, 1)
        else:
            jid = j.source_id if j.source_id is not None else int(m.getJointId(j.name))
            sq, sv, nq = int(m.idx_qs[jid]), int(m.idx_vs[jid]), int(m.nqs[jid])
        slots.append(_Slot(j.type, j.child, aq, av, sq, sv, nq))
        aq, av = aq + _SIZES.get(j.type, (0, 0))[0], av + _SIZES.get(j.type, (0, 0))[1]
    return slots, int(m.nq), int(m.nv)


def _wxyz(q: np.ndarray, fmt: str) -> np.ndarray:
    return np.asarray(q, float) if fmt == "mjcf" else np.array([q[3], q[0], q[1], q[2]])


def _source_quat(q: np.ndarray, fmt: str) -> np.ndarray:
    return q if fmt == "mjcf" else np.array([q[1], q[2], q[3], q[0]])


def _check(result: Any, what: str, values: Any, n: int) -> np.ndarray:
    arr = np.asarray(values, dtype=np.float64).reshape(-1)
    if arr.shape != (n,):
        raise ValueError(f"{what}: expected {n} values, got {arr.size}")
    return arr


def _require_articulated(result: Any) -> None:
    if not getattr(result, "articulated", False) or result.model is None:
        raise ValueError(
            f"{result.source.name}: joint mappings need an articulated load "
            "(load_urdf / load_mjcf with kinematic=False, the default)"
        )


def qpos_from_joint_positions(result: Any, positions: Any, world: Any = None) -> np.ndarray:
    """Source ``qpos``/``q`` from abdsim joint positions (and free bodies from ``world``)."""
    _require_articulated(result)
    slots, nq, _ = _source_slots(result)
    n = sum(_SIZES.get(s.kind, (0, 0))[0] for s in slots)
    x = _check(result, "joint positions", positions, n)
    q = np.array(result.q, dtype=np.float64)
    fmt = result.format
    for s in slots:
        if s.kind in ("revolute", "prismatic"):
            if s.nq == 2:  # Pinocchio's unbounded revolute: (cos, sin)
                phi = np.arctan2(q[s.sq + 1], q[s.sq]) + x[s.aq]
                q[s.sq : s.sq + 2] = (np.cos(phi), np.sin(phi))
            else:
                q[s.sq] += x[s.aq]
        elif s.kind == "ball":
            load = _wxyz(q[s.sq : s.sq + 4], fmt)
            rotated = pose_math.quaternion_product_wxyz(load, x[s.aq : s.aq + 4])
            q[s.sq : s.sq + 4] = _source_quat(rotated, fmt)
        elif s.kind == "free" and world is not None:
            p, quat = world.pose(s.body)
            q[s.sq : s.sq + 3] = p
            q[s.sq + 3 : s.sq + 7] = _source_quat(quat, fmt)
    return q


def joint_positions_from_qpos(result: Any, qpos: Any) -> np.ndarray:
    """abdsim joint positions (``world.joint_positions()`` layout) from a source ``qpos``/``q``."""
    _require_articulated(result)
    slots, nq, _ = _source_slots(result)
    q = _check(result, "qpos", qpos, nq)
    load = np.asarray(result.q, dtype=np.float64)
    out: list[float] = []
    for s in slots:
        if s.kind in ("revolute", "prismatic"):
            if s.nq == 2:
                d = np.arctan2(q[s.sq + 1], q[s.sq]) - np.arctan2(load[s.sq + 1], load[s.sq])
                out.append(float((d + np.pi) % (2 * np.pi) - np.pi))
            else:
                out.append(float(q[s.sq] - load[s.sq]))
        elif s.kind == "ball":
            a = _wxyz(load[s.sq : s.sq + 4], result.format)
            b = _wxyz(q[s.sq : s.sq + 4], result.format)
            a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
            rel = pose_math.quaternion_product_wxyz(_conj(a), b)
            out.extend((rel if rel[0] >= 0 else -rel).tolist())
    return np.array(out)


def qvel_from_joint_velocities(result: Any, velocities: Any, world: Any = None) -> np.ndarray:
    """Source ``qvel``/``v`` from abdsim joint velocities (and free bodies from ``world``)."""
    _require_articulated(result)
    slots, _, nv = _source_slots(result)
    n = sum(_SIZES.get(s.kind, (0, 0))[1] for s in slots)
    w = _check(result, "joint velocities", velocities, n)
    v = np.zeros(nv)
    for s in slots:
        if s.kind in ("revolute", "prismatic"):
            v[s.sv] = w[s.av]
        elif s.kind == "ball":
            v[s.sv : s.sv + 3] = w[s.av : s.av + 3]
        elif s.kind == "free" and world is not None:
            R = pose_math.nearest_rotations(world.transforms()[s.body][:3, :3])[0]
            lin, ang = world.twist(s.body)
            v[s.sv : s.sv + 3] = lin if result.format == "mjcf" else R.T @ lin
            v[s.sv + 3 : s.sv + 6] = R.T @ ang
    return v


def joint_velocities_from_qvel(result: Any, qvel: Any) -> np.ndarray:
    """abdsim joint velocities (``world.joint_velocities()`` layout) from ``qvel`` / ``v``."""
    _require_articulated(result)
    slots, _, nv = _source_slots(result)
    v = _check(result, "qvel", qvel, nv)
    out: list[float] = []
    for s in slots:
        if s.kind in ("revolute", "prismatic"):
            out.append(float(v[s.sv]))
        elif s.kind == "ball":
            out.extend(v[s.sv : s.sv + 3].tolist())
    return np.array(out)


def set_world_state(result: Any, world: Any, qpos: Any, qvel: Any = None) -> None:
    """Put ``world`` (of ``result``'s scene) at the source configuration ``qpos``/``q`` and
    velocity ``qvel``/``v`` (zero by default): the source's own forward kinematics gives every
    loaded body's pose and dT/dt."""
    from abdsim.bridges._bodies import pose_matrix, velocity_matrix

    _require_articulated(result)
    m = result.model
    T = np.array(world.transforms())
    V = np.array(world.velocities())
    if result.format == "mjcf":
        import mujoco

        d = mujoco.MjData(m)
        d.qpos[:] = _check(result, "qpos", qpos, m.nq)
        d.qvel[:] = 0.0 if qvel is None else _check(result, "qvel", qvel, m.nv)
        mujoco.mj_forward(m, d)
        res = np.zeros(6)
        for b, i in result.source_map.items():
            R = np.array(d.xmat[b]).reshape(3, 3)
            T[i] = pose_matrix(R, d.xpos[b])
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, b, res, 0)
            V[i] = velocity_matrix(R, res[:3], res[3:])
        # Joint frames (bridges/_joint_frames.py): the body frame after the joint that moves it.
        from abdsim.bridges._joint_frames import frame_state

        loaded = set(result.source_map.values())
        for j in result.joints:
            if j.child not in loaded:
                b = int(m.jnt_bodyid[j.source_id])
                upto = int(j.source_id) - int(m.body_jntadr[b]) + 1
                T[j.child], V[j.child] = frame_state(mujoco, m, d.qpos, d.qvel, b, upto)
    else:
        import pinocchio as pin

        from abdsim.bridges.urdf import joint_kinematics

        q = _check(result, "q", qpos, m.nq)
        v = np.zeros(m.nv) if qvel is None else _check(result, "v", qvel, m.nv)
        kin = joint_kinematics(pin, m, q, v)
        for j, i in result.source_map.items():
            if j == 0:
                continue
            R = np.array(kin.oMi[j].rotation)
            T[i] = np.array(kin.oMi[j].homogeneous)
            V[i] = velocity_matrix(R, R @ kin.v[j].angular, R @ kin.v[j].linear)
    world.set_state(T, V)
