"""Geometry: simplicial complexes (rest meshes with instances) and their constructors."""

from abdsim.geometry.attributes import AttributeCollection
from abdsim.geometry.primitives import (
    box,
    capsule,
    cylinder,
    edge_mesh,
    from_trimesh,
    sphere,
    tet_mesh,
    triangle_mesh,
)
from abdsim.geometry.simplicial_complex import SimplicialComplex

__all__ = [
    "AttributeCollection",
    "SimplicialComplex",
    "box",
    "capsule",
    "cylinder",
    "edge_mesh",
    "from_trimesh",
    "sphere",
    "tet_mesh",
    "triangle_mesh",
]
