"""The projected barrier Hessian of one contact stencil against ipctk's PSD projection of the
same stencil's exact Hessian (the projection runs on the relative motions of its vertices,
stencil_barrier.cpp): point–triangle, point–edge and edge–edge (crossing and near-parallel,
with the mollifier) pairs between two affine bodies; and random pairs of every distance type,
whose projection runs in the distance Hessian's structure (barrier_projection.h)."""

import ipctk
import numpy as np
import pytest

D_HAT = 0.02


def vertex_jacobian(geoms, body_geometry):
    """d(world vertices)/dq for every body's vertices, x = p + A x̄ (q = p, rows of A)."""
    rows = []
    n = len(body_geometry)
    for b, g in enumerate(body_geometry):
        for xb in geoms[g]["V"]:
            for i in range(3):
                row = np.zeros(12 * n)
                row[12 * b + i] = 1.0
                row[12 * b + 3 + 3 * i : 12 * b + 6 + 3 * i] = xb
                rows.append(row)
    return np.array(rows)


def small_rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


TRIANGLE = {
    "V": np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0]]),
    "F": np.array([[0, 1, 2]], np.int32),
}
POINT = {"V": np.zeros((1, 3))}
EDGE = {"V": np.array([[-0.05, 0.0, 0.0], [0.05, 0.0, 0.0]]), "E": np.array([[0, 1]], np.int32)}

CASES = {
    # point over the triangle's inside (4 vertices), beside its edge (point–edge: 3)
    "point_triangle": ([TRIANGLE, POINT], [0.03, 0.03, 0.006], None, "point_triangle"),
    "point_edge": ([TRIANGLE, POINT], [0.05, -0.004, 0.005], None, "point_triangle"),
    "edge_edge": ([EDGE, EDGE], [0.01, 0.0, 0.006], small_rotation([0, 0, 1], 1.0), "edge_edge"),
    "edge_edge_parallel": (
        [EDGE, EDGE],
        [0.01, 0.002, 0.006],
        small_rotation([0, 0, 1], 1e-3),
        "edge_edge",
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_projected_stencil_hessian_matches_ipctk(scenes, case):
    geoms, p, A, kind = CASES[case]
    A1 = small_rotation([1.0, 0.3, 0.2], 0.2) @ (np.eye(3) if A is None else A)
    q = np.stack(
        [scenes.q_of([0.0, 0.0, 0.0], small_rotation([0.2, 1.0, 0.1], 0.05)), scenes.q_of(p, A1)]
    )
    result = _projection_against_ipctk(scenes, geoms, q, kind)
    assert result is not None  # the pair is the only stencil, and its projection matters
    H, expected = result
    np.testing.assert_allclose(H, expected, rtol=0, atol=1e-9 * np.abs(expected).max())


def _projection_against_ipctk(scenes, geoms, q, kind):
    """(projected Hessian, ipctk's projection of the exact one, both in body space), or None
    when the pair is not the only active stencil or its Hessian is already PSD."""
    settings = {"d_hat": D_HAT, "kappa": 1e4, "mu": 0.0}
    projected = scenes.term(geoms, [0, 1], q, **settings)
    exact = scenes.term(geoms, [0, 1], q, project_hessian=False, **settings)
    for t in (projected, exact):
        t.update(q)
    counts = projected.counts()
    if counts[kind] != 1 or counts["point_triangle"] + counts["edge_edge"] != 1:
        return None
    x = q.ravel()
    J = vertex_jacobian(geoms, [0, 1])
    J_plus = np.linalg.pinv(J)
    H_vertices = J_plus.T @ exact.hessian(x) @ J_plus
    H_vertices = 0.5 * (H_vertices + H_vertices.T)
    if np.linalg.eigvalsh(H_vertices).min() > -1e-6 * np.abs(H_vertices).max():
        return None
    return projected.hessian(x), J.T @ ipctk.project_to_psd(H_vertices) @ J


@pytest.mark.parametrize("kind", ["point_triangle", "edge_edge"])
def test_random_stencils_projection_matches_ipctk(scenes, kind):
    """Random point–triangle pairs (the point over the inside, beside an edge, or beyond a
    corner: point–plane, point–line and point–point pieces) and random crossing or skew
    edge pairs (line–line, and the point–line / point–point pieces past an end), each within
    d̂: the structured projection equals ipctk's projection of the exact Hessian."""
    rng = np.random.default_rng(7 if kind == "point_triangle" else 8)
    geoms = [TRIANGLE, POINT] if kind == "point_triangle" else [EDGE, EDGE]
    checked = 0
    for _ in range(400):
        gap = rng.uniform(0.05, 0.9) * D_HAT
        R0 = scenes.rotation(rng, rng.uniform(0, 0.5))
        if kind == "point_triangle":
            uv = rng.uniform(-0.03, 0.13, size=2)  # the triangle spans [0, 0.1]² below u + v = 0.1
            local = np.array([uv[0], uv[1], 0.0])
            beside = uv.min() < 0 or uv.sum() > 0.1
            local[2] = gap if not beside else gap * rng.uniform(0.0, 0.7)
            q1 = scenes.q_of(R0 @ local, scenes.rotation(rng))
        else:
            along = rng.uniform(-0.06, 0.06)  # past ±0.05: beyond the first edge's end
            R1 = R0 @ small_rotation([0, 0, 1], rng.uniform(0.2, np.pi - 0.2))
            q1 = scenes.q_of(R0 @ np.array([along, rng.uniform(-0.01, 0.01), gap]), R1)
        q = np.stack([scenes.q_of([0.0, 0.0, 0.0], R0), q1])
        result = _projection_against_ipctk(scenes, geoms, q, kind)
        if result is None:
            continue
        H, expected = result
        np.testing.assert_allclose(H, expected, rtol=0, atol=1e-9 * np.abs(expected).max())
        checked += 1
    assert checked >= 100
