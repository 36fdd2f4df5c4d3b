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


def check_mesh_arrays(sc: object, where: str = "geometry", thickness: bool = True) -> None:
    """Re-check a SimplicialComplex whose attributes may have been edited in place.

    Rest positions (shape, NaN/inf), every simplex index against the current vertex count,
    and (if ``thickness``) a per-vertex ``thickness``: finite, positive for shells and rods
    (meta ``is_codim = 1``), >= 0 otherwise.

    Raises:
        ValueError: naming ``where`` and the offending element.
    """
    v = np.asarray(sc.vertices["position"])  # type: ignore[attr-defined]
    if v.ndim != 2 or v.shape[1] != 3 or len(v) == 0:
        raise ValueError(f"{where}: rest positions must have shape (n, 3), got {v.shape}")
    bad = ~np.isfinite(v).all(axis=1)
    if bad.any():
        raise ValueError(
            f"{where}: rest position of vertex {int(np.argmax(bad))} is NaN or infinite"
        )
    nv = len(v)
    for what, cells in (
        ("tetrahedron", sc.tetrahedra),  # type: ignore[attr-defined]
        ("triangle", sc.triangles),  # type: ignore[attr-defined]
        ("edge", sc.edges),  # type: ignore[attr-defined]
    ):
        c = np.asarray(cells)
        if c.size and (c.min() < 0 or c.max() >= nv):
            row = int(np.argmax(((c < 0) | (c >= nv)).any(axis=1)))
            raise ValueError(
                f"{where}: {what} {row} refers to vertex {c[row].tolist()} but the mesh has "
                f"{nv} vertices (were vertices removed after the mesh was built?)"
            )
    if thickness and "thickness" in sc.vertices:  # type: ignore[attr-defined]
        r = np.asarray(sc.vertices["thickness"], dtype=np.float64).reshape(-1)  # type: ignore[attr-defined]
        if r.shape != (nv,):
            raise ValueError(f"{where}: thickness needs {nv} values (one per vertex), got {r.size}")
        meta = sc.meta  # type: ignore[attr-defined]
        codim = "is_codim" in meta and int(meta["is_codim"]) == 1
        bad = ~(np.isfinite(r) & ((r > 0) if codim else (r >= 0)))
        if bad.any():
            i = int(np.argmax(bad))
            need = "positive" if codim else ">= 0"
            raise ValueError(
                f"{where}: thickness of vertex {i} must be {need} and finite, got {r[i]}"
            )


def check_transforms(T: np.ndarray, what: str = "transforms") -> None:
    """Affine transforms (n, 4, 4) must be proper and non-degenerate.

    The linear part A must have det A > 0 (a mirror turns surfaces inside out and the mass
    matrix's orientation with them) and a condition number below 1e6 (a flat A makes the
    body's surfaces and bounding volumes degenerate).

    Raises:
        ValueError: naming the instance and its det / singular values.
    """
    A = np.asarray(T, dtype=np.float64)[:, :3, :3]
    if len(A) == 0:
        return
    sv = np.linalg.svd(A, compute_uv=False)
    det = np.linalg.det(A)
    flat = sv[:, -1] <= 1e-6 * sv[:, 0]
    if flat.any():
        i = int(np.argmax(flat))
        raise ValueError(
            f"{what} {i}: the 3x3 part is degenerate (singular values {sv[i].tolist()}): a "
            "body cannot be flattened to a plane, a line or a point"
        )
    improper = det <= 0
    if improper.any():
        i = int(np.argmax(improper))
        raise ValueError(
            f"{what} {i}: the 3x3 part has det {det[i]:.6g} <= 0 (a mirror); transforms must "
            "be proper (rotation, scale, shear with det > 0)"
        )
