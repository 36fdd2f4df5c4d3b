"""Winding numbers and nesting against the half-space test of a convex mesh."""

from __future__ import annotations

import numpy as np
import trimesh

from abdsim.geometry.containment import nested_pairs, winding_numbers


def test_winding_numbers_agree_with_the_convex_half_space_test():
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=0.7)
    mesh.apply_transform(
        trimesh.transformations.random_rotation_matrix(np.random.default_rng(3).random(3))
    )
    points = np.random.default_rng(7).uniform(-1.0, 1.0, size=(400, 3))
    w = winding_numbers(points, mesh.vertices, mesh.faces)
    # convex: inside iff behind every face plane (trimesh's outward face normals)
    signed = np.einsum("fj,pfj->pf", mesh.face_normals, points[:, None] - mesh.triangles[:, 0])
    inside = (signed < 0).all(axis=1)
    np.testing.assert_array_equal(w > 0.5, inside)
    # away from the surface the number is 1 or 0 to round-off
    far = np.abs(np.linalg.norm(points, axis=1) - 0.7) > 0.05
    np.testing.assert_allclose(w[far], inside[far].astype(float), atol=1e-9)


def test_nested_pairs_finds_the_inner_body_and_respects_the_filter():
    box = trimesh.creation.box(extents=(2.0, 2.0, 2.0))
    small = trimesh.creation.box(extents=(0.2, 0.2, 0.2))
    outside = small.vertices + [3.0, 0, 0]
    bodies = [box.vertices, small.vertices + [0.5, 0.5, 0.0], outside]
    boxes = np.array([[v.min(axis=0), v.max(axis=0)] for v in bodies])
    probes = np.array([v[0] for v in bodies])
    solids = {0: (box.vertices, box.faces), 1: (bodies[1], small.faces)}
    assert nested_pairs(boxes, solids, probes, lambda a, b: True) == [(1, 0)]
    assert nested_pairs(boxes, solids, probes, lambda a, b: False) == []
