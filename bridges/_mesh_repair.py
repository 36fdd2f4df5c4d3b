"""Repairs the loaders apply to real robot meshes before they become affine-body surfaces.

* :func:`drop_zero_area` removes triangles of (numerically) zero area, which real meshes carry
  (collinear slivers) and abdsim's surface check rejects.
* :func:`closed_hull` is a convex hull that always comes out as a closed, outward-oriented
  triangle surface without zero-area triangles (trimesh's hull of thousands of nearly
  coplanar points can drop facets and come out open).
"""

from __future__ import annotations

import numpy as np
import trimesh
from scipy.spatial import ConvexHull, QhullError

#: A triangle whose area is at most this times the squared extent of its mesh is dropped.
#: (abdsim's surface check rejects 1e-14 of the *body's* extent; the margin covers a body
#: made of several meshes.)
ZERO_AREA = 1e-10


def _areas(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    p = v[f]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def _extent(v: np.ndarray) -> float:
    return max(float(np.ptp(v, axis=0).max()), 1e-300) if len(v) else 1.0


def drop_zero_area(
    name: str, vertices: np.ndarray, triangles: np.ndarray, notes: list[str]
) -> np.ndarray:
    """``triangles`` without the zero-area ones (a note says how many were removed)."""
    f = np.asarray(triangles, dtype=np.int64)
    if len(f) == 0:
        return f
    bad = _areas(np.asarray(vertices, dtype=np.float64), f) <= ZERO_AREA * _extent(vertices) ** 2
    if bad.any():
        notes.append(f"geometry {name!r}: removed {int(bad.sum())} zero-area triangle(s)")
        f = f[~bad]
    return f


def closed_hull(name: str, vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The convex hull of ``vertices`` as a closed, outward-oriented triangle surface.

    trimesh's hull first; if it comes out open or with zero-area triangles (nearly coplanar or
    collinear points), Qhull's hull of the points merged on a grid of ``1e-6`` of the extent and
    moved by a deterministic jitter of ``1e-9``
    (then ``1e-8``, ``1e-7``) of the extent, which makes every facet a proper triangle; the
    surface keeps the jittered points (a shape change far below any contact distance).

    Raises:
        ValueError: the points span no volume (flat or fewer than 4 distinct points).
    """
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    try:
        hull = trimesh.Trimesh(v, np.zeros((0, 3), dtype=np.int64), process=False).convex_hull
        out, faces = np.asarray(hull.vertices, dtype=np.float64), np.asarray(hull.faces)
        if is_proper_closed(out, faces):
            return out, faces
    except Exception:  # trimesh's hull raises several types on degenerate input
        pass
    rng = np.random.default_rng(0)
    extent = _extent(v)
    # Near-duplicate points make slivers whatever the jitter: merge them on a 1e-6 grid.
    v = np.unique(np.round(v / (1e-6 * extent)), axis=0) * (1e-6 * extent)
    for jitter in (1e-9, 1e-8, 1e-7):
        pts = v + rng.uniform(-1.0, 1.0, v.shape) * (jitter * extent)
        out, faces = _qhull(name, pts)
        if is_proper_closed(out, faces):
            break
    return out, faces


def is_proper_closed(v: np.ndarray, f: np.ndarray) -> bool:
    """Closed, consistently oriented and without zero-area triangles."""
    from abdsim.geometry import validation as mesh_check

    if len(f) < 4 or (_areas(v, f) <= ZERO_AREA * _extent(v) ** 2).any():
        return False
    try:
        mesh_check.check_closed_oriented(f)
    except ValueError:
        return False
    return True


def _qhull(name: str, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    try:
        hull = ConvexHull(pts)
    except (QhullError, ValueError) as e:
        raise ValueError(f"geometry {name!r}: its points span no volume ({e})") from e
    faces = np.asarray(hull.simplices, dtype=np.int64)
    p = pts[faces]
    normals = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    flip = np.einsum("ij,ij->i", normals, hull.equations[:, :3]) < 0
    faces[flip] = faces[flip][:, ::-1]
    used, inverse = np.unique(faces, return_inverse=True)
    return pts[used], inverse.reshape(-1, 3)
