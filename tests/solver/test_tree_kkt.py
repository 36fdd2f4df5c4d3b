"""The constrained Newton solve (solver/constrained_solve.h, solver/tree_kkt.h) against a
dense numpy solve of the same KKT system [H Jᵀ; J 0] [x; λ] = [rhs; −c]: articulations
(forests) take the block-tree elimination, anything else the sparse LDLᵀ. Soft rows (a
rank-one Hessian k g gᵀ that the solves eliminate like a row of compliance 1/k) are checked
against the dense solve with k g gᵀ added to H."""

from __future__ import annotations

import numpy as np
import pytest

from abdsim import _core

RNG_SEED = 7


def point_rows(child: int, parent: int, xc: np.ndarray, xp: np.ndarray, rng) -> list:
    """Three rows x_child(x̄_c) − x_parent(x̄_p) = 0 (parent −1: the world), values random."""
    rows = []
    for k in range(3):
        ja = np.zeros(12)
        ja[k] = 1.0
        ja[3 + 3 * k : 6 + 3 * k] = xc
        jb = np.zeros(12)
        if parent >= 0:
            jb[k] = -1.0
            jb[3 + 3 * k : 6 + 3 * k] = -xp
        rows.append((child, parent, ja, jb, float(rng.normal(scale=1e-3))))
    return rows


def hinge_rows(child: int, parent: int, rng) -> list:
    """A revolute joint's six rows: its anchor and a second point on the axis."""
    anchor, axis = rng.normal(size=3), rng.normal(size=3)
    return point_rows(child, parent, anchor, anchor + 0.3 * rng.normal(size=3), rng) + point_rows(
        child, parent, anchor + axis, anchor + axis + 0.3 * rng.normal(size=3), rng
    )


def frame_rows(child: int, parent: int, rng) -> list:
    """Nine rows (A_c ē_c − A_p ē_p)_k = 0 for three random direction pairs."""
    rows = []
    for _ in range(3):
        ec, ep = rng.normal(size=3), rng.normal(size=3)
        for k in range(3):
            ja, jb = np.zeros(12), np.zeros(12)
            ja[3 + 3 * k : 6 + 3 * k] = ec
            jb[3 + 3 * k : 6 + 3 * k] = -ep
            rows.append((child, parent, ja, jb, float(rng.normal(scale=1e-3))))
    return rows


def weld_rows(child: int, parent: int, rng) -> list:
    """A fixed joint's twelve rows: a point and the three frame directions."""
    rows = point_rows(child, parent, rng.normal(size=3), rng.normal(size=3), rng)
    return rows + frame_rows(child, parent, rng)


def system(n: int, coupled_pairs, rng):
    """SPD diagonal blocks and coupling blocks (each pair with its transpose) whose assembled
    matrix is SPD (block-diagonally dominant)."""
    couplings = []
    bump = np.zeros(n)
    for i, j in coupled_pairs:
        C = rng.normal(size=(12, 12))
        couplings += [(i, j, C), (j, i, C.T)]
        s = np.linalg.norm(C, 2)
        bump[i] += s
        bump[j] += s
    diagonal = []
    for b in range(n):
        R = rng.normal(size=(12, 12))
        diagonal.append(R @ R.T + (bump[b] + 1.0) * np.eye(12))
    return diagonal, couplings


def soft_rows(pairs, rng, k_scale: float = 1.0) -> list:
    """One rank-one Hessian row per (a, b) pair, with a random gradient and k > 0."""
    return [
        (a, b, rng.normal(size=12), rng.normal(size=12), float(k_scale * rng.uniform(0.5, 5.0)))
        for a, b in pairs
    ]


def dense_reference(diagonal, couplings, fixed, rows, rhs, soft=()) -> np.ndarray:
    n = len(diagonal)
    free = [b for b in range(n) if not fixed[b]]
    index = {b: i for i, b in enumerate(free)}
    nf = 12 * len(free)
    H = np.zeros((nf, nf))
    for b in free:
        H[12 * index[b] : 12 * index[b] + 12, 12 * index[b] : 12 * index[b] + 12] = diagonal[b]
    for i, j, C in couplings:
        if i in index and j in index:
            H[12 * index[i] : 12 * index[i] + 12, 12 * index[j] : 12 * index[j] + 12] = C
    for a, b, ga, gb, k in soft:
        g = np.zeros(nf)
        for body, grad in ((a, ga), (b, gb)):
            if body in index:
                g[12 * index[body] : 12 * index[body] + 12] += grad
        H += k * np.outer(g, g)
    J, c = [], []
    for a, b, ja, jb, value in rows:
        row = np.zeros(nf)
        for body, grad in ((a, ja), (b, jb)):
            if body in index:
                row[12 * index[body] : 12 * index[body] + 12] += grad
        if np.any(row):
            J.append(row)
            c.append(value)
    J = np.array(J).reshape(len(J), nf)
    m = len(J)
    K = np.block([[H, J.T], [J, np.zeros((m, m))]])
    b = np.concatenate([np.concatenate([rhs[f] for f in free]), -np.array(c)])
    u = np.linalg.solve(K, b)
    x = np.zeros((n, 12))
    for f in free:
        x[f] = u[12 * index[f] : 12 * index[f] + 12]
    return x


def check(diagonal, couplings, fixed, rows, expected_path: str, soft=()) -> None:
    rng = np.random.default_rng(RNG_SEED + 1)
    rhs = rng.normal(size=(len(diagonal), 12))
    ref = dense_reference(diagonal, couplings, fixed, rows, rhs, soft)
    scale = np.abs(ref).max()
    soft = list(soft)
    x, path = _core.solve_kkt(diagonal, couplings, fixed, rows, rhs, soft_rows=soft)
    assert path == expected_path
    assert np.abs(x - ref).max() <= 1e-9 * scale, np.abs(x - ref).max() / scale
    x_sparse, path = _core.solve_kkt(
        diagonal, couplings, fixed, rows, rhs, allow_tree=False, soft_rows=soft
    )
    assert path == "sparse"
    assert np.abs(x_sparse - ref).max() <= 1e-9 * scale, np.abs(x_sparse - ref).max() / scale


def test_chain_with_couplings_takes_the_tree_path():
    rng = np.random.default_rng(RNG_SEED)
    n = 6
    diagonal, couplings = system(n, [(0, 1), (2, 3), (3, 4)], rng)
    rows = hinge_rows(0, -1, rng)
    for b in range(1, n):
        rows += hinge_rows(b, b - 1, rng)
    check(diagonal, couplings, [0] * n, rows, "tree")


def test_branching_tree_rooted_at_its_world_joint_with_a_weld_and_a_fixed_body():
    rng = np.random.default_rng(RNG_SEED)
    n = 7
    # The world joint is on body 4; body 6 is fixed, so the joint 5 -> 6 holds 5 to a constant.
    diagonal, couplings = system(n, [(4, 0), (0, 1), (4, 2)], rng)
    rows = hinge_rows(4, -1, rng) + hinge_rows(0, 4, rng) + hinge_rows(1, 0, rng)
    rows += hinge_rows(2, 4, rng) + weld_rows(3, 2, rng) + hinge_rows(5, 6, rng)
    fixed = [0] * n
    fixed[6] = 1
    check(diagonal, couplings, fixed, rows, "tree")


def test_loop_takes_the_sparse_path():
    rng = np.random.default_rng(RNG_SEED)
    n = 4
    diagonal, couplings = system(n, [(0, 1)], rng)
    rows = hinge_rows(0, -1, rng) + hinge_rows(1, 0, rng) + hinge_rows(2, 1, rng)
    rows += point_rows(3, 2, rng.normal(size=3), rng.normal(size=3), rng)
    rows += point_rows(3, 0, rng.normal(size=3), rng.normal(size=3), rng)  # closes a loop
    check(diagonal, couplings, [0] * n, rows, "sparse")


def test_redundant_rows_fall_back_to_the_sparse_path():
    """A hinge doubled between the same bodies: the tree path declines (dependent rows of
    one node), the regularised sparse path still meets every row."""
    rng = np.random.default_rng(RNG_SEED)
    diagonal, couplings = system(2, [], rng)
    rows = hinge_rows(0, -1, rng) + hinge_rows(1, 0, rng)
    rows += rows[6:]
    x, path = _core.solve_kkt(diagonal, couplings, [0, 0], rows, np.ones((2, 12)))
    assert path == "sparse"
    for a, b, ja, jb, value in rows:
        residual = ja @ x[a] + (jb @ x[b] if b >= 0 else 0.0) + value
        assert abs(residual) <= 1e-9, residual


def test_soft_rows_along_a_chain_match_the_dense_solve_with_their_hessian_in_h():
    """A hinge chain whose joints also carry a rank-one row each (an actuator's Gauss–Newton
    Hessian), some with a coupling block beside it, one against a fixed body and one to the
    world: both paths solve the system with k g gᵀ in H."""
    rng = np.random.default_rng(RNG_SEED)
    n = 6
    diagonal, couplings = system(n, [(1, 2), (3, 4)], rng)
    rows = hinge_rows(0, -1, rng)
    for b in range(1, n):
        rows += hinge_rows(b, b - 1, rng)
    soft = soft_rows([(b, b - 1) for b in range(1, n)] + [(2, 1), (4, 5)], rng)
    fixed = [0] * n
    # A soft row from the last body to the first closes a loop: the sparse path solves it.
    check(diagonal, couplings, fixed, rows, "sparse", soft + soft_rows([(5, 0)], rng, 1e-3))
    soft += soft_rows([(0, -1)], rng)
    check(diagonal, couplings, fixed, rows, "tree", soft)
    fixed[n - 1] = 1  # the soft row to it lands on body n − 2's diagonal block
    check(diagonal, couplings, fixed, rows, "tree", soft)


def test_a_full_node_folds_its_soft_rows_into_its_coupling_block():
    """A weld carries twelve hard rows, its node has no room left for the two soft rows to
    its parent: they enter as blocks, and the tree path still solves the same system."""
    rng = np.random.default_rng(RNG_SEED)
    diagonal, couplings = system(3, [(1, 2)], rng)
    rows = hinge_rows(0, -1, rng) + weld_rows(1, 0, rng) + hinge_rows(2, 1, rng)
    soft = soft_rows([(1, 0), (0, 1), (2, 1)], rng, k_scale=10.0)
    check(diagonal, couplings, [0, 0, 0], rows, "tree", soft)


def ball_rows(child: int, parent: int, rng) -> list:
    """A ball joint's three rows: one shared point."""
    return point_rows(child, parent, rng.normal(size=3), rng.normal(size=3), rng)


def slider_rows(child: int, parent: int, rng) -> list:
    """A prismatic joint's eleven rows: the three frame directions (nine rows on A) and the
    two offsets n·(x_c − x_p) = 0 across the axis (n on p and n_k x̄ on A's row k; the
    parent's side carries the bilinear term's extra gradient, here random)."""
    rows = frame_rows(child, parent, rng)
    anchor_c, anchor_p = rng.normal(size=3), rng.normal(size=3)
    for _ in range(2):
        n = rng.normal(size=3)
        ja, jb = np.zeros(12), np.zeros(12)
        for k in range(3):
            ja[k] = n[k]
            ja[3 + 3 * k : 6 + 3 * k] = n[k] * anchor_c
            jb[k] = -n[k]
            jb[3 + 3 * k : 6 + 3 * k] = -n[k] * anchor_p + 0.1 * rng.normal(size=3)
        rows.append((child, parent, ja, jb, float(rng.normal(scale=1e-3))))
    return rows


def check_tight(diagonal, couplings, fixed, rows, soft) -> None:
    """The tree path against the dense KKT solve to 1e-10 of the solution's size."""
    rng = np.random.default_rng(RNG_SEED + 2)
    rhs = rng.normal(size=(len(diagonal), 12))
    ref = dense_reference(diagonal, couplings, fixed, rows, rhs, soft)
    x, path = _core.solve_kkt(diagonal, couplings, fixed, rows, rhs, soft_rows=list(soft))
    assert path == "tree"
    error = np.abs(x - ref).max() / np.abs(ref).max()
    assert error <= 1e-10, error


def test_panda_shaped_tree_with_an_actuator_row_per_joint_matches_the_dense_solve():
    """Seven hinges from the world, two sliders (the fingers) on the last link, each joint
    with a soft row (its position actuator's Hessian): the Panda's shape of tree."""
    rng = np.random.default_rng(RNG_SEED)
    n = 9
    diagonal, couplings = system(n, [], rng)
    rows = hinge_rows(0, -1, rng)
    for b in range(1, 7):
        rows += hinge_rows(b, b - 1, rng)
    rows += slider_rows(7, 6, rng) + slider_rows(8, 6, rng)
    parents = [-1, 0, 1, 2, 3, 4, 5, 6, 6]
    soft = soft_rows([(b, parents[b]) for b in range(1, n)], rng)
    soft[0:0] = [(0, -1, rng.normal(size=12), np.zeros(12), 2.0)]
    check_tight(diagonal, couplings, [0] * n, rows, soft)


def test_chain_of_fifty_hinges_matches_the_dense_solve():
    rng = np.random.default_rng(RNG_SEED)
    n = 50
    diagonal, couplings = system(n, [], rng)
    rows = hinge_rows(0, -1, rng)
    for b in range(1, n):
        rows += hinge_rows(b, b - 1, rng)
    soft = soft_rows([(b, b - 1) for b in range(1, n, 3)], rng)
    check_tight(diagonal, couplings, [0] * n, rows, soft)


def test_branched_tree_of_every_joint_kind_matches_the_dense_solve():
    """Hinge, ball, slider and weld nodes branching from one body, a coupling block beside
    two of them, soft rows on some: every kind of node the tree path eliminates."""
    rng = np.random.default_rng(RNG_SEED)
    n = 8
    diagonal, couplings = system(n, [(0, 2), (3, 5)], rng)
    rows = hinge_rows(0, -1, rng) + ball_rows(1, 0, rng) + slider_rows(2, 0, rng)
    rows += weld_rows(3, 0, rng) + hinge_rows(4, 1, rng) + ball_rows(5, 3, rng)
    rows += slider_rows(6, 4, rng) + hinge_rows(7, 2, rng)
    soft = soft_rows([(1, 0), (2, 0), (4, 1), (6, 4), (7, 2), (5, 3)], rng)
    check_tight(diagonal, couplings, [0] * n, rows, soft)


@pytest.mark.parametrize("coupled", [False, True])
def test_every_row_count_per_node_matches_the_dense_solve(coupled):
    """Node b of a chain carries the first b of a weld's twelve independent rows (b = 1..12),
    so every row count a node can have is factorised once: each of the kernels' padded sizes
    (4, 8, 12) with each of its compile-time row counts (tree_kkt.cpp, factor_rows). With
    dense coupling blocks the same, through the V = L⁻¹ H_bP path."""
    rng = np.random.default_rng(RNG_SEED + 3)
    n = 13
    pairs = [(b, b - 1) for b in range(1, n)] if coupled else []
    diagonal, couplings = system(n, pairs, rng)
    rows = hinge_rows(0, -1, rng)
    for b in range(1, n):
        rows += weld_rows(b, b - 1, rng)[:b]
    check_tight(diagonal, couplings, [0] * n, rows, ())
