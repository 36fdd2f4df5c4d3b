"""Input checks for meshes: every problem is a ValueError that names what is wrong."""

from __future__ import annotations

import numpy as np


def as_vertices(vertices: object) -> np.ndarray:
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must have shape (n, 3), got {v.shape}")
    if v.shape[0] == 0:
        raise ValueError("mesh has no vertices")
    bad = ~np.isfinite(v).all(axis=1)
    if bad.any():
        raise ValueError(f"vertex {int(np.argmax(bad))} has a NaN or infinite coordinate")
    return np.ascontiguousarray(v)


def as_simplices(cells: object, arity: int, n_vertices: int, what: str) -> np.ndarray:
    """Integer (m, arity) index array, in range, without repeated vertices in a cell."""
    if cells is None:
        return np.zeros((0, arity), dtype=np.int32)
    raw = np.asarray(cells)
    if raw.size == 0:
        return np.zeros((0, arity), dtype=np.int32)
    if raw.ndim != 2 or raw.shape[1] != arity:
        raise ValueError(f"{what} must have shape (m, {arity}), got {raw.shape}")
    if not np.issubdtype(raw.dtype, np.integer):
        if not np.all(np.isfinite(raw)) or not np.all(raw == np.round(raw)):
            raise ValueError(f"{what} must hold integer vertex indices")
    c = raw.astype(np.int64)
    out = (c < 0) | (c >= n_vertices)
    if out.any():
        row = int(np.argmax(out.any(axis=1)))
        raise ValueError(
            f"{what} {row} has vertex index {c[row].tolist()} out of range [0, {n_vertices})"
        )
    s = np.sort(c, axis=1)
    repeated = (s[:, 1:] == s[:, :-1]).any(axis=1)
    if repeated.any():
        row = int(np.argmax(repeated))
        raise ValueError(f"{what} {row} repeats a vertex: {c[row].tolist()} (degenerate)")
    return np.ascontiguousarray(c.astype(np.int32))


def unique_edges(triangles: np.ndarray) -> np.ndarray:
    """Undirected edges of a triangle mesh, sorted and unique, shape (m, 2)."""
    if len(triangles) == 0:
        return np.zeros((0, 2), dtype=np.int32)
    e = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    return np.unique(np.sort(e, axis=1), axis=0).astype(np.int32)


def check_closed_oriented(triangles: np.ndarray) -> None:
    """A solid's surface: every edge shared by exactly two faces, in opposite directions."""
    if len(triangles) == 0:
        raise ValueError("a solid needs triangles or tetrahedra; the mesh has none")
    directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    undirected = np.sort(directed, axis=1)
    _, counts = np.unique(undirected, axis=0, return_counts=True)
    if (counts == 1).any():
        raise ValueError(
            f"mesh is open: {int((counts == 1).sum())} boundary edge(s); a solid needs a closed "
            "surface (use AffineBodyShell for an open surface)"
        )
    if (counts > 2).any():
        raise ValueError(
            f"mesh is non-manifold: {int((counts > 2).sum())} edge(s) shared by more than two faces"
        )
    _, dcounts = np.unique(directed, axis=0, return_counts=True)
    if (dcounts > 1).any():
        raise ValueError(
            "mesh is inconsistently oriented: neighbouring faces traverse a shared edge in the "
            "same direction"
        )


def triangle_areas(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    v = vertices[triangles]
    return 0.5 * np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1)


def check_nondegenerate_triangles(vertices: np.ndarray, triangles: np.ndarray) -> None:
    areas = triangle_areas(vertices, triangles)
    scale = max(float(np.ptp(vertices, axis=0).max()), 1e-300) ** 2
    bad = areas <= 1e-14 * scale
    if bad.any():
        raise ValueError(f"triangle {int(np.argmax(bad))} has zero area (degenerate)")


def tet_signed_volumes(vertices: np.ndarray, tets: np.ndarray) -> np.ndarray:
    p = vertices[tets]
    return (
        np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))
        / 6.0
    )


def boundary_faces(tets: np.ndarray) -> np.ndarray:
    """Outward-oriented boundary triangles of a positively oriented tet mesh."""
    if len(tets) == 0:
        return np.zeros((0, 3), dtype=np.int32)
    # For a positive tet (0,1,2,3) these faces have outward normals.
    faces = np.concatenate(
        [tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]]
    )
    key = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return np.ascontiguousarray(faces[counts[inverse.ravel()] == 1].astype(np.int32))
