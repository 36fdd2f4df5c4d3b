"""A body for a moving link group that has mass but no collision geometry.

An articulated robot cannot drop such a group (go2's 0.77 kg ``FL_hip``, z1's ``link01``):
its children would hang from the wrong body by the wrong joint. The group becomes a body
whose surface is its *equivalent inertia box* (the solid box of the same mass and principal
moments, centred at the centre of mass along the principal axes), which only gives the affine
body a volume for its shape energy: the mass properties are the source's exactly, and the box
collides with nothing (the loaders exclude it from every pair and the ground).
"""

from __future__ import annotations

import numpy as np

from abdsim.bridges._bodies import Surface, primitive_surface, transform_points

#: Smallest half-extent of a proxy box, as a fraction of its largest (a point mass or a rod
#: still gets a solid).
MIN_ASPECT = 1e-2
#: Smallest half-extent (m): a box that collides with nothing still meets the World's check
#: that contact's reach d_hat is small against every dynamic body (d_hat up to 5 mm).
MIN_HALF_EXTENT = 1e-2


def inertia_box(name: str, mass: float, centre: np.ndarray, inertia: np.ndarray) -> Surface:
    """The equivalent inertia box of a group (body frame), named ``name``."""
    moments, frame = np.linalg.eigh(0.5 * (inertia + inertia.T))
    if np.linalg.det(frame) < 0:
        frame[:, 2] *= -1
    second = np.maximum(0.5 * (moments.sum() - 2.0 * moments), 0.0)  # Σ_i = m a_i² / 3
    half = np.sqrt(3.0 * second / max(mass, 1e-12))
    half = np.maximum(half, max(MIN_ASPECT * half.max(), MIN_HALF_EXTENT))
    v, f = primitive_surface("box", half, name)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = frame, centre
    return Surface(name, transform_points(T, v), f)
