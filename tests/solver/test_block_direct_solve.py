"""BlockSystem's sparse direct solve keeps the analysis of its pattern (ordering, symbolic
factorisation, the permuted matrix it factorises) between Newton iterations: solves that
reuse it must equal a dense solve and, bit for bit, a fresh analysis of the same matrix."""

import numpy as np

from abdsim import _core


def random_system(rng, n, pairs, fixed):
    """SPD block system: couplings (i, j, H) with their transposes, diagonally dominant."""
    couplings, dense = [], np.zeros((12 * n, 12 * n))
    for i, j in pairs:
        H = rng.normal(size=(12, 12))
        couplings += [(i, j, H), (j, i, H.T.copy())]
        if not (fixed[i] or fixed[j]):
            dense[12 * i : 12 * i + 12, 12 * j : 12 * j + 12] = H
            dense[12 * j : 12 * j + 12, 12 * i : 12 * i + 12] = H.T
    diagonal = []
    for b in range(n):
        A = rng.normal(size=(12, 12))
        D = A @ A.T + (np.abs(dense[12 * b : 12 * b + 12]).sum(axis=1).max() + 1.0) * np.eye(12)
        diagonal.append(D)
        dense[12 * b : 12 * b + 12, 12 * b : 12 * b + 12] = D
    return diagonal, couplings, dense


def dense_solution(dense, rhs, fixed):
    free = np.repeat(np.asarray(fixed) == 0, 12)
    x = np.zeros(dense.shape[0])
    x[free] = np.linalg.solve(dense[np.ix_(free, free)], rhs.ravel()[free])
    return x.reshape(-1, 12)


def test_reused_analysis_equals_a_fresh_one_and_a_dense_solve(rng):
    n, fixed = 9, [0, 0, 1, 0, 0, 0, 0, 0, 0]
    patterns = [
        [(0, 1), (1, 3), (3, 4), (4, 8), (5, 6), (2, 7)],
        [(0, 1), (1, 3), (3, 4), (4, 8), (5, 6), (2, 7)],  # same pattern, new values
        [(0, 1), (1, 3), (3, 4), (4, 8), (5, 6), (6, 7), (0, 8)],  # a new coupling
        [(0, 1), (1, 3), (3, 4), (4, 8), (5, 6), (6, 7), (0, 8)],
    ]
    solver = _core.BlockDirectSolve()
    analysed = []
    for pairs in patterns:
        diagonal, couplings, dense = random_system(rng, n, pairs, fixed)
        rhs = rng.normal(size=(n, 12))
        x, new_analysis = solver.solve(diagonal, couplings, fixed, rhs)
        analysed.append(new_analysis)
        reference = dense_solution(dense, rhs, fixed)
        np.testing.assert_allclose(x, reference, rtol=0, atol=1e-12 * np.abs(reference).max())
        fresh, fresh_analysis = _core.BlockDirectSolve().solve(diagonal, couplings, fixed, rhs)
        assert fresh_analysis
        np.testing.assert_array_equal(x, fresh)
    assert analysed == [True, False, True, False]


def test_fill_in_and_indefinite_systems_equal_a_dense_solve(rng):
    """A random graph of 40 bodies (cycles: the elimination fills blocks the matrix lacks)
    and fixed bodies among them; then the same pattern made indefinite (an LDLᵀ needs no
    definiteness, only non-zero pivots): both equal numpy's dense solve."""
    n = 40
    fixed = [1 if b % 13 == 5 else 0 for b in range(n)]
    pairs = sorted({tuple(sorted(rng.choice(n, 2, replace=False))) for _ in range(90)})
    diagonal, couplings, dense = random_system(rng, n, pairs, fixed)
    rhs = rng.normal(size=(n, 12))
    solver = _core.BlockDirectSolve()
    x, _ = solver.solve(diagonal, couplings, fixed, rhs)
    reference = dense_solution(dense, rhs, fixed)
    np.testing.assert_allclose(x, reference, rtol=0, atol=1e-12 * np.abs(reference).max())

    # Flip the sign of some bodies' diagonal blocks: eigenvalues of both signs.
    for b in range(0, n, 3):
        diagonal[b] = -diagonal[b]
        dense[12 * b : 12 * b + 12, 12 * b : 12 * b + 12] *= -1
    free = np.repeat(np.asarray(fixed) == 0, 12)
    eigenvalues = np.linalg.eigvalsh(dense[np.ix_(free, free)])
    assert eigenvalues.min() < 0 < eigenvalues.max()
    x, analysed = solver.solve(diagonal, couplings, fixed, rhs)
    assert not analysed  # same pattern
    reference = dense_solution(dense, rhs, fixed)
    np.testing.assert_allclose(x, reference, rtol=0, atol=1e-10 * np.abs(reference).max())
