"""Repairs of real robot meshes: closed hulls, zero-area triangles, small round primitives."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull, cKDTree

from abdsim.bridges import load_urdf
from abdsim.bridges._bodies import closed_surface, primitive_surface
from abdsim.bridges._mesh_repair import closed_hull, drop_zero_area, is_proper_closed
from abdsim.geometry import validation as mesh_check

from .conftest import ROBOTS


def _z1_file(relative: str):
    """A file of example-robot-data's z1 description, else skip."""
    if ROBOTS is None:
        pytest.skip("example-robot-data is not installed")
    path = ROBOTS / "z1_description" / relative
    if not path.is_file():
        pytest.skip(f"{path} not shipped by this example-robot-data")
    return path


def test_hull_of_a_dense_real_mesh_is_closed_with_the_hull_volume():
    """z1's gripper stator: trimesh's hull of its 21,745 points came out open (9 edges)."""
    path = _z1_file("meshes/collision/z1_GripperStator.STL")
    points = np.asarray(trimesh.load(path, force="mesh").vertices)
    v, f = closed_hull("stator", points)
    mesh_check.check_closed_oriented(f)
    mesh_check.check_nondegenerate_triangles(v, f)
    mesh = trimesh.Trimesh(v, f, process=False)
    # qhull's own volume; the repair moves points by at most ~1e-6 of the extent (the merge
    # grid), i.e. the volume by a few 1e-6 relative.
    assert mesh.volume == pytest.approx(ConvexHull(points).volume, rel=1e-5)
    moved, _ = cKDTree(points).query(v)  # each hull vertex near one of the mesh's points
    assert moved.max() < 1e-6 * np.ptp(points, axis=0).max()


def test_hull_of_collinear_and_coplanar_points_is_proper():
    # A cube sampled densely on its edges and faces: every hull facet is coplanar with others
    # and many points are collinear, the case that leaves zero-area triangles.
    g = np.linspace(0.0, 1.0, 21)
    face = np.array([[x, y] for x in g for y in g])
    pts = np.concatenate(
        [np.insert(face, axis, value, axis=1) for axis in range(3) for value in (0.0, 1.0)]
    )
    v, f = closed_hull("cube", pts)
    assert is_proper_closed(v, f)
    assert trimesh.Trimesh(v, f, process=False).volume == pytest.approx(1.0, rel=1e-6)


def test_zero_area_triangles_are_dropped_with_a_note():
    box = trimesh.creation.box((1.0, 1.0, 1.0))
    v = np.asarray(box.vertices)
    sliver = np.array([[0, 0, 0]])  # one vertex repeated: zero area
    f = np.concatenate([np.asarray(box.faces), sliver])
    notes: list[str] = []
    kept = drop_zero_area("box", v, f, notes)
    np.testing.assert_array_equal(kept, box.faces)
    assert notes == ["geometry 'box': removed 1 zero-area triangle(s)"]
    # Through the loaders' entry point the box survives exactly (closed after the drop).
    out_v, out_f = closed_surface("box", v, f, "error", notes=[])
    assert trimesh.Trimesh(out_v, out_f, process=False).volume == pytest.approx(1.0)


@pytest.mark.parametrize("kind", ["capsule", "cylinder", "sphere"])
@pytest.mark.parametrize("radius", [1e-3, 5e-4, 1e-4])
def test_small_round_primitives_are_closed_and_exact_in_size(kind, radius):
    """so101's 1 mm gripper capsules came out open (vertices merged at an absolute tolerance)."""
    v, f = primitive_surface(kind, [radius, 0.01], "tiny")
    mesh_check.check_closed_oriented(f)
    mesh_check.check_nondegenerate_triangles(v, f)
    assert np.ptp(v[:, 0]) == pytest.approx(2 * radius, rel=1e-12)
    if kind != "sphere":
        half = 0.01 + (radius if kind == "capsule" else 0.0)
        assert np.ptp(v[:, 2]) == pytest.approx(2 * half, rel=1e-12)


def test_urdf_repairs_are_noted_and_warned_once():
    """Hull notes printed twice before (once by the repair, once by the loader)."""
    path = _z1_file("urdf/z1.urdf")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = load_urdf(path)
    messages = [str(w.message) for w in caught if issubclass(w.category, UserWarning)]
    assert sorted(messages) == sorted(res.notes)
    assert len(set(messages)) == len(messages)
    assert any("gripperStator" in n and "convex hull" in n for n in res.notes)
