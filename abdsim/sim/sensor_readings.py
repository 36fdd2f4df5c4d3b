"""The values of a SensorSet at a World's state (``World.sensordata``); see abdsim.sim.sensors
for what each type measures."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from abdsim.sim.contact_forces import ContactForces
from abdsim.sim.sensors import ACCELERATION_TYPES, JOINT_TYPES, SensorSpec


@dataclass
class BodyState:
    """What the sensors read from: the state, its last step's acceleration, gravity, and
    (when touch / force / torque sensors need them) contacts, wrenches and mass data."""

    q: np.ndarray  # (n, 12)
    q_dot: np.ndarray  # (n, 12)
    acceleration: np.ndarray | None  # (n, 12) generalized, of the last step
    gravity: np.ndarray  # (3,)
    contacts: ContactForces | None = None
    wrenches: np.ndarray | None = None  # (n, 6) about the centres of mass
    mass_matrices: dict[int, np.ndarray] | None = None  # body -> 12x12
    rest_centers: np.ndarray | None = None  # (n, 3)


def nearest_rotation(A: np.ndarray) -> np.ndarray:
    """Polar rotation factor of each 3x3 A, (k, 3, 3)."""
    U, _, Vt = np.linalg.svd(A)
    R = U @ Vt
    flip = np.linalg.det(R) < 0
    U[flip, :, 2] *= -1
    return U @ Vt


def axial(T: np.ndarray) -> np.ndarray:
    """τ_k = ε_kij T_ij of each 3x3 T, (k, 3)."""
    return np.stack([T[:, 1, 2] - T[:, 2, 1], T[:, 2, 0] - T[:, 0, 2], T[:, 0, 1] - T[:, 1, 0]], 1)


def generalized_to_wrench(q: np.ndarray, F: np.ndarray, rest_center: np.ndarray) -> np.ndarray:
    """(k, 6) force and torque about x = A c̄ + p of generalized forces F (k, 12) on q = [p, A]:
    a point force f at x̄ contributes f to F_p and f x̄ᵀ to ∂/∂A, so the torque about the
    centre is axial(A Gᵀ) − (A c̄) × F_p."""
    A = q[:, 3:].reshape(-1, 3, 3)
    G = F[:, 3:].reshape(-1, 3, 3)
    offset = np.einsum("kij,kj->ki", A, rest_center)
    torque = axial(A @ np.transpose(G, (0, 2, 1))) - np.cross(offset, F[:, :3])
    return np.concatenate([F[:, :3], torque], axis=1)


def _frames(state: BodyState, bodies: np.ndarray, pos: np.ndarray, rot: np.ndarray):
    """World origin (k, 3) and rotation (k, 3, 3) of frames fixed to bodies."""
    q = state.q[bodies]
    A = q[:, 3:].reshape(-1, 3, 3)
    x = np.einsum("kij,kj->ki", A, pos) + q[:, :3]
    return x, nearest_rotation(A) @ rot


def _in_zone(local: np.ndarray, shape: str, size: np.ndarray) -> np.ndarray:
    """Which points (m, 3) in a zone's frame lie in it (MuJoCo site shapes, z the axis)."""
    if shape == "sphere":
        return np.linalg.norm(local, axis=1) <= size[0]
    if shape == "box":
        return (np.abs(local) <= size).all(axis=1)
    if shape == "ellipsoid":
        return ((local / size) ** 2).sum(axis=1) <= 1.0
    radial = np.linalg.norm(local[:, :2], axis=1)
    if shape == "cylinder":
        return (radial <= size[0]) & (np.abs(local[:, 2]) <= size[1])
    # capsule: within radius of the segment z ∈ [−half length, half length]
    z = np.clip(local[:, 2], -size[1], size[1])
    return np.linalg.norm(local - np.stack([0 * z, 0 * z, z], 1), axis=1) <= size[0]


def _touch(spec: SensorSpec, x: np.ndarray, R: np.ndarray, contacts: ContactForces) -> float:
    mine = (contacts.bodies == spec.body).any(axis=1)
    if not mine.any():
        return 0.0
    local = (contacts.points[mine] - x) @ R  # Rᵀ (point − x), row-wise
    shape, size = spec.zone
    return float(contacts.normal_force[mine][_in_zone(local, shape, size)].sum())


def sensor_values(specs: list[SensorSpec], state: BodyState) -> np.ndarray:
    """sensordata: every sensor's values, concatenated in order (NaN for unsupported)."""
    out = [np.full(s.dim, np.nan) for s in specs]
    # Joint sensors are read from joints, not frames (joint_sensor_readings): NaN here.
    idx = [i for i, s in enumerate(specs) if s.type != "unsupported" and s.type not in JOINT_TYPES]
    if not idx:
        return np.concatenate(out) if out else np.zeros(0)
    bodies = np.array([specs[i].body for i in idx])
    pos = np.array([specs[i].pos for i in idx])
    rot = np.array([specs[i].rot for i in idx])
    x, R = _frames(state, bodies, pos, rot)
    q_dot = state.q_dot[bodies]
    A_dot = q_dot[:, 3:].reshape(-1, 3, 3)
    A = state.q[bodies, 3:].reshape(-1, 3, 3)
    velocity = np.einsum("kij,kj->ki", A_dot, pos) + q_dot[:, :3]
    W = A_dot @ np.linalg.inv(A)
    omega = 0.5 * axial(np.transpose(W, (0, 2, 1)))  # skew part of Ȧ A⁻¹ = [ω]×
    to_site = lambda k, v: R[k].T @ v  # noqa: E731 - world vector → site frame
    for k, i in enumerate(idx):
        s = specs[i]
        if s.type == "framepos" or s.type == "framequat":
            xr, Rr = np.zeros(3), np.eye(3)
            if s.ref is not None:
                xr_, Rr_ = _frames(state, np.array([s.ref[0]]), s.ref[1][None], s.ref[2][None])
                xr, Rr = xr_[0], Rr_[0]
            if s.type == "framepos":
                out[i] = Rr.T @ (x[k] - xr)
            else:
                xyzw = Rotation.from_matrix(Rr.T @ R[k]).as_quat()
                out[i] = np.array([xyzw[3], *xyzw[:3]])
        elif s.type == "velocimeter":
            out[i] = to_site(k, velocity[k])
        elif s.type == "gyro":
            out[i] = to_site(k, omega[k])
        elif s.type == "touch":
            out[i] = np.array([_touch(s, x[k], R[k], state.contacts)])
        elif s.type in ACCELERATION_TYPES:
            if state.acceleration is None:  # no step yet
                out[i] = np.zeros(s.dim)
            else:
                out[i] = _acceleration_sensor(s, k, bodies, x, R, state)
        if s.cutoff > 0 and s.type != "framequat":
            low = 0.0 if s.type == "touch" else -s.cutoff
            out[i] = np.clip(out[i], low, s.cutoff)
    return np.concatenate(out)


def _acceleration_sensor(s, k, bodies, x, R, state: BodyState) -> np.ndarray:
    b = bodies[k]
    acc = state.acceleration[b]
    if s.type == "accelerometer":
        A_ddot = acc[3:].reshape(3, 3)
        return R[k].T @ (A_ddot @ s.pos + acc[:3] - state.gravity)
    # force / torque: what the parent must apply, M (ä − g_q) − contact, at the site
    g_q = np.zeros(12)
    g_q[:3] = state.gravity
    F = state.mass_matrices[b] @ (acc - g_q)
    c_bar = state.rest_centers[b]
    wrench = generalized_to_wrench(state.q[b][None], F[None], c_bar[None])[0] - state.wrenches[b]
    if s.type == "force":
        return R[k].T @ wrench[:3]
    center = state.q[b, 3:].reshape(3, 3) @ c_bar + state.q[b, :3]
    return R[k].T @ (wrench[3:] + np.cross(center - x[k], wrench[:3]))
