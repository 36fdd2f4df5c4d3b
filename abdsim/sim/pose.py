"""Poses and twists of affine bodies in the conventions robotics users know.

An affine body's state is ``T = [[A, p], [0, 1]]`` and its rate ``dT/dt = [[Ȧ, ṗ], [0, 0]]``.
``A`` stays within the shape energy's tolerance of a rotation; the *pose* reports the
rotation nearest to it (the polar factor ``R`` of ``A = R S``):

* pose: position ``p`` (the body frame's origin) and the unit quaternion of ``R`` in MuJoCo's
  order ``[w, x, y, z]``, with ``w >= 0``;
* twist: the origin's linear velocity ``ṗ`` and the angular velocity ``ω``, both in the world
  frame, ``[ω]×`` being the skew part of ``Ȧ A⁻¹`` (exactly ``Ȧ = [ω]× A`` for a rigid
  motion). MuJoCo's free-joint ``qvel`` has the same linear part and ``Rᵀ ω`` (body frame)
  as its angular part.
"""

from __future__ import annotations

import numpy as np


def nearest_rotations(A: np.ndarray) -> np.ndarray:
    """Polar rotation factor R of each 3x3 ``A`` (the rotation nearest to it), (n, 3, 3)."""
    U, _, Vt = np.linalg.svd(np.asarray(A, dtype=np.float64).reshape(-1, 3, 3))
    d = np.sign(np.linalg.det(U @ Vt))
    d[d == 0] = 1.0
    U[:, :, 2] *= d[:, None]
    return U @ Vt


def quaternion_product_wxyz(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a ⊗ b`` of two w-first quaternions, (4,)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ]
    )


def quaternions_wxyz(R: np.ndarray) -> np.ndarray:
    """Unit quaternions ``[w, x, y, z]`` (w >= 0) of rotation matrices, (n, 4).

    Shepperd's method: the largest of the four squared components is computed from the
    trace terms, the others from off-diagonal sums and differences (no cancellation).
    """
    R = np.asarray(R, dtype=np.float64).reshape(-1, 3, 3)
    m00, m11, m22 = R[:, 0, 0], R[:, 1, 1], R[:, 2, 2]
    squares = np.stack(
        [1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22],
        axis=1,
    )  # 4 w², 4 x², 4 y², 4 z²
    pick = np.argmax(squares, axis=1)
    s = 2.0 * np.sqrt(np.maximum(squares[np.arange(len(R)), pick], 1e-300))
    d21, d02, d10 = R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]
    s01, s02, s12 = R[:, 0, 1] + R[:, 1, 0], R[:, 0, 2] + R[:, 2, 0], R[:, 1, 2] + R[:, 2, 1]
    big = s * s / 4
    rows = {  # [w, x, y, z] * s for each choice of the largest component
        0: (big, d21, d02, d10),
        1: (d21, big, s01, s02),
        2: (d02, s01, big, s12),
        3: (d10, s02, s12, big),
    }
    q = np.empty((len(R), 4))
    for k, cols in rows.items():
        m = pick == k
        q[m] = np.stack([c[m] for c in cols], axis=1) / s[m, None]
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[q[:, 0] < 0] *= -1
    return q


def angular_velocities(A: np.ndarray, A_dot: np.ndarray) -> np.ndarray:
    """World-frame ω of each body from Ȧ = [ω]× A: the skew part of Ȧ A⁻¹, (n, 3)."""
    W = np.asarray(A_dot, dtype=np.float64) @ np.linalg.inv(np.asarray(A, dtype=np.float64))
    return 0.5 * np.stack(
        [W[:, 2, 1] - W[:, 1, 2], W[:, 0, 2] - W[:, 2, 0], W[:, 1, 0] - W[:, 0, 1]], axis=1
    )


def poses(transforms: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions (n, 3) and quaternions ``[w, x, y, z]`` (n, 4) of (n, 4, 4) transforms."""
    T = np.asarray(transforms, dtype=np.float64).reshape(-1, 4, 4)
    return T[:, :3, 3].copy(), quaternions_wxyz(nearest_rotations(T[:, :3, :3]))


def twists(transforms: np.ndarray, velocities: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World-frame linear (n, 3) and angular (n, 3) velocities from T and dT/dt."""
    T = np.asarray(transforms, dtype=np.float64).reshape(-1, 4, 4)
    V = np.asarray(velocities, dtype=np.float64).reshape(-1, 4, 4)
    return V[:, :3, 3].copy(), angular_velocities(T[:, :3, :3], V[:, :3, :3])
