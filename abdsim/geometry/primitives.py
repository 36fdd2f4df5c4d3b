"""Constructors: from numpy arrays, from trimesh meshes and from trimesh's primitives."""

from __future__ import annotations

import numpy as np
import trimesh

from abdsim.geometry.simplicial_complex import SimplicialComplex


def tet_mesh(vertices: np.ndarray, tetrahedra: np.ndarray) -> SimplicialComplex:
    """A solid tetrahedral mesh; its boundary triangles are extracted for contact."""
    return SimplicialComplex(vertices, tetrahedra=tetrahedra)


def triangle_mesh(vertices: np.ndarray, triangles: np.ndarray) -> SimplicialComplex:
    """A triangle mesh: a closed solid's surface, or a shell."""
    return SimplicialComplex(vertices, triangles=triangles)


def edge_mesh(vertices: np.ndarray, edges: np.ndarray) -> SimplicialComplex:
    """An edge (polyline) mesh, for rods."""
    return SimplicialComplex(vertices, edges=edges)


def from_trimesh(mesh: trimesh.Trimesh) -> SimplicialComplex:
    """A triangle-mesh SimplicialComplex from a ``trimesh.Trimesh``."""
    if not isinstance(mesh, trimesh.Trimesh):
        raise TypeError(f"expected a trimesh.Trimesh, got {type(mesh).__name__}")
    return triangle_mesh(np.asarray(mesh.vertices), np.asarray(mesh.faces))


def box(extents: tuple[float, float, float] | float = 1.0) -> SimplicialComplex:
    """An axis-aligned box centred at the origin (12 triangles)."""
    ext = np.broadcast_to(np.asarray(extents, dtype=np.float64), (3,))
    if not (np.isfinite(ext).all() and (ext > 0).all()):
        raise ValueError(f"box extents must be positive and finite, got {ext.tolist()}")
    return from_trimesh(trimesh.creation.box(extents=ext))


def sphere(radius: float = 0.5, subdivisions: int = 2) -> SimplicialComplex:
    """An icosphere centred at the origin."""
    _positive("sphere radius", radius)
    return from_trimesh(trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius))


def cylinder(radius: float = 0.5, height: float = 1.0, sections: int = 32) -> SimplicialComplex:
    """A closed cylinder along z, centred at the origin."""
    _positive("cylinder radius", radius)
    _positive("cylinder height", height)
    return from_trimesh(trimesh.creation.cylinder(radius=radius, height=height, sections=sections))


def capsule(radius: float = 0.25, height: float = 1.0, count: int = 16) -> SimplicialComplex:
    """A capsule along z (``height`` between the hemisphere centres), centred at the origin."""
    _positive("capsule radius", radius)
    _positive("capsule height", height)
    return from_trimesh(
        trimesh.creation.capsule(height=height, radius=radius, count=[count, count])
    )


def _positive(what: str, value: float) -> None:
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{what} must be positive and finite, got {value}")
