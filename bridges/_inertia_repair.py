"""Repair of a rigid group's degenerate inertia (the loaders' ``boundinertia``).

Real robot files carry inertias that are not physical on their own: point masses on sensor
frames (zero inertia), micro-gram dummy roots, moments that break the triangle inequality
after rounding. The loaders check the inertia of each *rigid group* that becomes a body (after
merging fixed links), never of a single link, and repair a group that is still degenerate
instead of refusing the robot, with a note.

The repair follows MuJoCo's ``boundmass`` / ``boundinertia`` idea, stated on the second
moments of mass, which is where an affine body needs positivity: with principal moments
``λ`` the second moments are ``Σ_i = (λ_j + λ_k - λ_i) / 2`` (``Σ_i ≥ 0`` is exactly the
triangle inequality). Each ``Σ_i`` is raised to at least ``m (ε L)²`` (``L`` the diagonal of
the group's surface bounding box, ``ε = BOUND_RADIUS_FRACTION``), i.e. the mass is spread
over at least a thin shell of ``ε L`` around each principal axis, and the inertia is rebuilt
as ``λ_i = Σ_j + Σ_k`` in the same principal frame. Moments that already satisfy the bound
are kept unchanged. A non-positive mass is replaced by ``BOUND_MASS``.
"""

from __future__ import annotations

import numpy as np

#: Smallest second-moment radius, as a fraction of the group's bounding-box diagonal.
BOUND_RADIUS_FRACTION = 1e-2
#: Mass (kg) given to a moving group whose source mass is zero (MuJoCo's ``boundmass``).
BOUND_MASS = 1e-3


def is_degenerate(inertia: np.ndarray) -> bool:
    """Whether ``inertia`` fails abdsim's physical-inertia check."""
    from abdsim.constitution import check_inertia

    try:
        check_inertia(np.asarray(inertia, dtype=np.float64))
    except ValueError:
        return True
    return False


def bound_inertia(mass: float, inertia: np.ndarray, size: float) -> tuple[float, np.ndarray]:
    """``(mass, inertia)`` with every principal second moment at least ``m (ε size)²``.

    Args:
        mass: the group's mass (kg); a non-positive or non-finite one becomes ``BOUND_MASS``.
        inertia: the (3, 3) inertia about the centre of mass (symmetrised first).
        size: a length of the group (m), the diagonal of its surface's bounding box.

    Returns:
        The repaired mass and inertia tensor (same principal frame as the input).
    """
    m = float(mass) if np.isfinite(mass) and mass > 0 else BOUND_MASS
    tensor = np.asarray(inertia, dtype=np.float64)
    tensor = np.where(np.isfinite(tensor), tensor, 0.0)
    moments, frame = np.linalg.eigh(0.5 * (tensor + tensor.T))
    second = 0.5 * (moments.sum() - 2.0 * moments)  # Σ_i = (λ_j + λ_k - λ_i) / 2
    floor = m * (BOUND_RADIUS_FRACTION * max(float(size), 1e-6)) ** 2
    second = np.maximum(second, floor)
    repaired = second.sum() - second  # λ_i = Σ_j + Σ_k
    return m, frame @ np.diag(repaired) @ frame.T


def surface_size(vertices: list[np.ndarray]) -> float:
    """Diagonal of the bounding box of the given vertex arrays (m)."""
    points = np.concatenate([np.asarray(v, dtype=np.float64).reshape(-1, 3) for v in vertices])
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
