import numpy as np
import pytest

import abdsim
from abdsim.geometry import SimplicialComplex

TET_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)


def test_tet_mesh_extracts_outward_boundary():
    sc = abdsim.geometry.tet_mesh(TET_V, [[0, 1, 2, 3]])
    assert sc.dim == 3
    assert sc.triangles.shape == (4, 3)
    assert sc.edges.shape == (6, 2)
    # outward: each face normal points away from the opposite vertex / the centroid
    v = sc.positions[sc.triangles]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    centroid = TET_V.mean(axis=0)
    assert np.all(np.einsum("ij,ij->i", n, v.mean(axis=1) - centroid) > 0)


def test_attribute_collections_behave_like_dicts():
    sc = abdsim.geometry.box(1.0)
    assert sc.positions.shape == (8, 3)
    assert "position" in sc.vertices
    sc.vertices["position"][0] += 0.0  # views are editable in place
    sc.meta["custom"] = np.float64(2.5)
    assert sc.meta["custom"] == 2.5
    sc.instances.create("tag", np.int32(7))
    sc.instances.resize(3)
    assert sc.instances["tag"].tolist() == [7, 7, 7]
    np.testing.assert_array_equal(sc.transforms, np.broadcast_to(np.eye(4), (3, 4, 4)))
    t = np.array(sc.transforms)
    t[1, :3, 3] = [1, 2, 3]
    sc.transforms = t
    assert sc.transforms[1, 2, 3] == 3.0
    with pytest.raises(ValueError, match="shape"):
        sc.instances["tag"] = np.zeros(5)
    with pytest.raises(KeyError, match="no attribute"):
        sc.meta["nothing"]


def test_new_instances_get_defaults_after_apply():
    sc = abdsim.geometry.box(1.0)
    abdsim.AffineBodyConstitution().apply_to(sc, kappa=1e8)
    sc.instances["kappa"][0] = 5e8
    sc.instances.resize(2)
    assert sc.instances["kappa"].tolist() == [5e8, 1e8]
    assert sc.instances["is_fixed"].tolist() == [0, 0]
    assert sc.instances["velocity"].shape == (2, 4, 4)


def test_from_trimesh_and_primitives():
    import trimesh

    mesh = trimesh.creation.icosphere(subdivisions=1, radius=0.3)
    sc = abdsim.geometry.from_trimesh(mesh)
    np.testing.assert_allclose(sc.positions, mesh.vertices)
    np.testing.assert_array_equal(sc.triangles, mesh.faces)
    assert abdsim.geometry.cylinder(0.1, 0.5).dim == 2
    assert abdsim.geometry.capsule(0.1, 0.5).dim == 2
    assert abdsim.geometry.edge_mesh(TET_V[:2], [[0, 1]]).dim == 1


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"vertices": np.zeros((4, 2))}, r"shape \(n, 3\)"),
        ({"vertices": [[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], "triangles": [[0, 1, 2]]}, "NaN"),
        ({"vertices": TET_V, "triangles": [[0, 1, 7]]}, "out of range"),
        ({"vertices": TET_V, "triangles": [[0, 1, 1]]}, "repeats a vertex"),
        ({"vertices": TET_V, "triangles": [[0, 1]]}, r"shape \(m, 3\)"),
        ({"vertices": TET_V, "tetrahedra": [[0, 2, 1, 3]]}, "negative orientation"),
        ({"vertices": TET_V}, "no edges, triangles or tetrahedra"),
        ({"vertices": TET_V, "triangles": [[0.5, 1, 2]]}, "integer"),
        ({"vertices": TET_V, "edges": [[0, 1]], "transforms": np.eye(3)}, "transforms"),
    ],
)
def test_bad_geometry_raises(kwargs, message):
    with pytest.raises(ValueError, match=message):
        SimplicialComplex(**kwargs)


def test_degenerate_tet_raises():
    flat = TET_V.copy()
    flat[3] = [0.5, 0.5, 0.0]
    with pytest.raises(ValueError, match="zero volume"):
        abdsim.geometry.tet_mesh(flat, [[0, 1, 2, 3]])


@pytest.mark.parametrize("bad", [0.0, -1.0, np.inf])
def test_bad_primitive_sizes(bad):
    with pytest.raises(ValueError, match="positive"):
        abdsim.geometry.box((1.0, bad, 1.0))
    with pytest.raises(ValueError, match="positive"):
        abdsim.geometry.sphere(bad)
