"""MJCF geoms that are not closed primitives: planes at any orientation and height fields.

abdsim's ground is one z-up half-space. MuJoCo planes that are tilted (dm_control walls), or a
second z-up plane at another height, become fixed thin boxes whose top face is the plane's
rectangle (``geom_size[:2]`` half-extents; an infinite plane, size 0, gets ten times the
model's extent), thickness one tenth of the smaller half-extent, below the plane.

Height fields (``hfield``) become fixed closed meshes: the ``nrow × ncol`` elevation grid
(``x`` along columns over ``[-size[0], size[0]]``, ``y`` along rows over
``[-size[1], size[1]]``, ``z = size[2] · data``) closed by side walls down to ``-size[3]`` and
a flat bottom, as MuJoCo's height-field solid.
"""

from __future__ import annotations

import numpy as np


def plane_box_size(size: np.ndarray, extent: float) -> tuple[np.ndarray, np.ndarray]:
    """Half-extents of the box standing for a plane, and its centre in the plane's frame."""
    infinite = 10.0 * max(float(extent), 1.0)
    hx = float(size[0]) if size[0] > 0 else infinite
    hy = float(size[1]) if size[1] > 0 else infinite
    thickness = 0.1 * min(hx, hy)
    return np.array([hx, hy, 0.5 * thickness]), np.array([0.0, 0.0, -0.5 * thickness])


def heightfield_surface(
    nrow: int, ncol: int, size: np.ndarray, data: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Closed, outward-oriented surface of a MuJoCo height field (geom frame)."""
    sx, sy, sz, base = (float(s) for s in size)
    x = np.linspace(-sx, sx, ncol)
    y = np.linspace(-sy, sy, nrow)
    X, Y = np.meshgrid(x, y)  # (nrow, ncol): row -> y, column -> x
    Z = sz * np.asarray(data, dtype=np.float64).reshape(nrow, ncol)
    top = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    idx = np.arange(nrow * ncol).reshape(nrow, ncol)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    faces = [np.column_stack([a, b, d]), np.column_stack([a, d, c])]  # counter-clockwise from +z
    # Boundary loop of the grid, counter-clockwise seen from +z.
    ring = np.concatenate([idx[0, :-1], idx[:-1, -1], idx[-1, :0:-1], idx[:0:-1, 0]])
    bottom = top[ring].copy()
    bottom[:, 2] = -base
    n_top, n_ring = len(top), len(ring)
    low = n_top + np.arange(n_ring)
    centre = n_top + n_ring
    nxt = np.roll(np.arange(n_ring), -1)
    # Side walls: each boundary edge (ring[i] -> ring[i+1]) down to the bottom ring.
    faces.append(np.column_stack([ring, low, low[nxt]]))
    faces.append(np.column_stack([ring, low[nxt], ring[nxt]]))
    faces.append(np.column_stack([np.full(n_ring, centre), low[nxt], low]))  # bottom fan, -z
    vertices = np.vstack([top, bottom, [[0.0, 0.0, -base]]])
    return vertices, np.concatenate(faces).astype(np.int64)
