"""The broad phase on dense, sheared bodies: every primitive pair within reach is found.

The broad phase keeps each body's BVH in rest space and bounds node boxes through the body's
affine map, recovered from its world vertices (abdsim/cpp/contact/broad_phase/affine_frame.h);
a flat body has no such map and is refit instead. Both paths must return a superset of the
pairs within d̂: the contact term's active pairs are compared with an independent brute force
(ipctk's exact distances on every pair that a vectorised box test cannot rule out).
"""

from __future__ import annotations

import numpy as np
import trimesh

D_HAT = 0.02


def _box_distance(points, lo, hi):
    """(n, m): distance from each point to each axis-aligned box."""
    gap = np.maximum(0.0, np.maximum(lo[None] - points[:, None], points[:, None] - hi[None]))
    return np.linalg.norm(gap, axis=2)


def _brute_force(term, q, d_hat, ipctk):
    X = term.world_vertices(q)
    F, E = np.array(term.faces), np.array(term.edges)
    vb = np.repeat(np.arange(len(term.vertex_offsets) - 1), np.diff(term.vertex_offsets))
    pt, ee = set(), set()
    flo, fhi = X[F].min(axis=1), X[F].max(axis=1)
    near = (_box_distance(X, flo, fhi) < d_hat) & (vb[:, None] != vb[F[:, 0]][None])
    for v, f in zip(*np.nonzero(near), strict=True):
        a, b, c = F[f]
        if np.sqrt(ipctk.point_triangle_distance(X[v], X[a], X[b], X[c])) < d_hat:
            pt.add((int(v), int(f)))
    elo, ehi = X[E].min(axis=1), X[E].max(axis=1)
    apart = np.maximum(0.0, np.maximum(elo[:, None] - ehi[None], elo[None] - ehi[:, None]))
    near = (np.linalg.norm(apart, axis=2) < d_hat) & (vb[E[:, 0]][:, None] != vb[E[:, 0]][None])
    for i, j in zip(*np.nonzero(np.triu(near, 1)), strict=True):
        (a0, a1), (b0, b1) = E[i], E[j]
        if np.sqrt(ipctk.edge_edge_distance(X[a0], X[a1], X[b0], X[b1])) < d_hat:
            ee.add((int(i), int(j)))
    return pt, ee


def assert_active_pairs_match(term, q, d_hat, ipctk) -> int:
    """term's active pairs at q (after update(q)) are the brute force's; returns their count."""
    pt, ee = _brute_force(term, q, d_hat, ipctk)
    got = term.active_pairs()
    assert {tuple(p) for p in got["point_triangle"]} == pt
    assert {tuple(p) for p in got["edge_edge"]} == ee
    return len(pt) + len(ee)


def test_dense_sheared_bodies_match_brute_force(scenes, rng):
    """Four dense spheres under rotation, shear and stretch, and a flat square (refit path)."""
    import ipctk

    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.1)
    square = np.array([[-0.15, -0.15, 0], [0.15, -0.15, 0], [0.15, 0.15, 0], [-0.15, 0.15, 0]])
    geoms = [
        {"V": np.asarray(sphere.vertices), "F": np.asarray(sphere.faces, np.int32)},
        {"V": square, "F": np.array([[0, 1, 2], [0, 2, 3]], np.int32)},
    ]
    found = 0
    for _ in range(3):
        q = []
        for k in range(4):
            shear = np.eye(3) + rng.uniform(-0.25, 0.25, (3, 3))
            q.append(
                scenes.q_of([0.19 * k, *rng.uniform(-0.02, 0.02, 2)], scenes.rotation(rng) @ shear)
            )
        q.append(
            scenes.q_of([0.3, 0.0, -0.11 + rng.uniform(-0.01, 0.01)], scenes.rotation(rng, 0.1))
        )
        q = np.stack(q)
        term = scenes.term(geoms, [0, 0, 0, 0, 1], q, d_hat=D_HAT, kappa=1.0)
        term.update(q)
        found += assert_active_pairs_match(term, q, D_HAT, ipctk)
    assert found > 100
