"""SimplicialComplex: one rest geometry shared by n instances, each instance an affine body."""

from __future__ import annotations

import numpy as np

from abdsim.geometry import validation as check
from abdsim.geometry.attributes import AttributeCollection


class SimplicialComplex:
    """A rest mesh (vertices + edges/triangles/tetrahedra) and per-instance transforms.

    Attribute collections (dicts of numpy arrays):

    * ``sc.meta``: per geometry, shared by every instance (``volume``, ``abd_mass``, ...).
    * ``sc.instances``: one entry per instance (``transform``, ``kappa``, ``velocity``, ...).
    * ``sc.vertices``: one entry per vertex (``position`` = rest position x̄, ``thickness``).

    Args:
        vertices: (nv, 3) rest positions.
        edges: (ne, 2) vertex indices (rods); derived from triangles when omitted.
        triangles: (nf, 3) vertex indices, outward oriented for solids.
        tetrahedra: (nt, 4) positively oriented vertex indices.
        transforms: (n, 4, 4) instance transforms, or one (4, 4); identity by default.

    Raises:
        ValueError: on wrong shapes, non-finite vertices, out-of-range or repeated indices,
            negatively oriented or degenerate tetrahedra, mirror (det <= 0) or degenerate
            transforms.
    """

    def __init__(
        self,
        vertices: np.ndarray,
        edges: np.ndarray | None = None,
        triangles: np.ndarray | None = None,
        tetrahedra: np.ndarray | None = None,
        transforms: np.ndarray | None = None,
    ) -> None:
        v = check.as_vertices(vertices)
        nv = len(v)
        tets = check.as_simplices(tetrahedra, 4, nv, "tetrahedron")
        tris = check.as_simplices(triangles, 3, nv, "triangle")
        if len(tets):
            vol = check.tet_signed_volumes(v, tets)
            scale = max(float(np.ptp(v, axis=0).max()), 1e-300) ** 3
            if (vol <= 1e-14 * scale).any():
                i = int(np.argmax(vol <= 1e-14 * scale))
                kind = (
                    "zero volume (degenerate)"
                    if abs(vol[i]) <= 1e-14 * scale
                    else ("negative orientation (swap two vertices)")
                )
                raise ValueError(f"tetrahedron {i} has {kind}")
            if len(tris) == 0:
                tris = check.boundary_faces(tets)
        edge_cells = check.as_simplices(edges, 2, nv, "edge")
        if len(edge_cells) == 0:
            edge_cells = check.unique_edges(tris)
        if len(tets) == 0 and len(tris) == 0 and len(edge_cells) == 0:
            raise ValueError("mesh has no edges, triangles or tetrahedra")

        self._edges = edge_cells
        self._triangles = tris
        self._tetrahedra = tets
        self.meta = AttributeCollection("meta", 1, squeeze=True)
        self.vertices = AttributeCollection("vertices", nv)
        self.instances = AttributeCollection("instances", 1)
        self.vertices.create("position", np.zeros(3))
        self.vertices["position"] = v
        self.instances.create("transform", np.eye(4))
        if transforms is not None:
            t = np.asarray(transforms, dtype=np.float64)
            if t.shape == (4, 4):
                t = t[None]
            if t.ndim != 3 or t.shape[1:] != (4, 4):
                raise ValueError(f"transforms must have shape (n, 4, 4), got {t.shape}")
            self.instances.resize(len(t))
            self.transforms = t

    # -- topology ---------------------------------------------------------------------------
    @property
    def positions(self) -> np.ndarray:
        """Rest vertex positions x̄, (nv, 3) (same as ``vertices["position"]``)."""
        return self.vertices["position"]

    @property
    def edges(self) -> np.ndarray:
        return self._edges

    @property
    def triangles(self) -> np.ndarray:
        return self._triangles

    @property
    def tetrahedra(self) -> np.ndarray:
        return self._tetrahedra

    @property
    def dim(self) -> int:
        """3 for a tet mesh, 2 for a triangle mesh, 1 for an edge mesh."""
        if len(self._tetrahedra):
            return 3
        if len(self._triangles):
            return 2
        return 1

    # -- instances --------------------------------------------------------------------------
    @property
    def instance_count(self) -> int:
        return self.instances.size

    @property
    def transforms(self) -> np.ndarray:
        """Per-instance 4x4 transforms [[A, p], [0, 1]], shape (n, 4, 4)."""
        return self.instances["transform"]

    @transforms.setter
    def transforms(self, value: np.ndarray) -> None:
        t = np.asarray(value, dtype=np.float64)
        if t.shape == (4, 4) and self.instance_count == 1:
            t = t[None]
        if t.shape != (self.instance_count, 4, 4):
            raise ValueError(
                f"transforms must have shape ({self.instance_count}, 4, 4), got {t.shape}"
            )
        if not np.isfinite(t).all():
            raise ValueError("transforms contain NaN or infinite values")
        check.check_transforms(t, "transform of instance")
        self.instances["transform"] = t

    def __repr__(self) -> str:
        return (
            f"<SimplicialComplex dim={self.dim} vertices={self.vertices.size} "
            f"edges={len(self._edges)} triangles={len(self._triangles)} "
            f"tetrahedra={len(self._tetrahedra)} instances={self.instance_count}>"
        )
