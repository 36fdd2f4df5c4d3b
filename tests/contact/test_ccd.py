"""Additive CCD: analytic times of impact, conservativeness, and agreement with ipctk's
Tight-Inclusion CCD (a certified root finder).

Tight-Inclusion's `min_distance` is not a Euclidean separation (it reports impacts on
trajectories whose Euclidean distance never drops below it), so it is the oracle only for
ξ = 0; with ξ > 0 we check against a dense sampling of the trajectory instead."""

import ipctk
import numpy as np
import pytest

TRI = (np.zeros(3), np.array([1.0, 0, 0]), np.array([0.0, 1, 0]))


def test_point_falls_into_triangle(contact):
    # z(t) = 1 − 2t: touches at t = 0.5, or at 0.45 with a 0.1 minimum separation
    p0, p1 = np.array([0.2, 0.2, 1.0]), np.array([0.2, 0.2, -1.0])
    for xi, true_toi in [(0.0, 0.5), (0.1, 0.45)]:
        toi = contact.point_triangle_ccd(p0, *TRI, p1, *TRI, min_distance=xi)
        assert toi <= true_toi
        assert toi >= 0.9 * true_toi * (
            1 - 1e-12
        )  # a straight approach stops within the target gap
        # the gap left at toi is at least target × the initial gap
        z = 1.0 - 2.0 * toi
        assert z - xi >= 0.1 * (1.0 - xi) * (1 - 1e-12)


def test_moving_triangle_and_miss(contact):
    p = np.array([0.2, 0.2, 0.0])
    up = [v + np.array([0, 0, -1.0]) for v in TRI]
    # triangle at z = −1 rising to z = +1 through a static point: contact at t = 0.5
    toi = contact.point_triangle_ccd(p, *up, p, *[v + np.array([0, 0, 1.0]) for v in TRI])
    assert 0.45 <= toi <= 0.5
    # a point passing beside the triangle never hits it
    toi = contact.point_triangle_ccd(np.array([2.0, 2, 1]), *TRI, np.array([2.0, 2, -1]), *TRI)
    assert toi == 1.0
    # no motion
    assert (
        contact.point_triangle_ccd(np.array([0.2, 0.2, 1]), *TRI, np.array([0.2, 0.2, 1]), *TRI)
        == 1.0
    )
    # starting inside the minimum separation
    assert (
        contact.point_triangle_ccd(
            np.array([0.2, 0.2, 0.05]), *TRI, np.array([0.2, 0.2, 1]), *TRI, min_distance=0.1
        )
        == 0.0
    )


def test_crossing_edges(contact):
    ea0, ea1 = np.array([-1.0, 0, 1]), np.array([1.0, 0, 1])
    eb0, eb1 = np.array([0.0, -1, 0]), np.array([0.0, 1, 0])
    down = np.array([0, 0, -2.0])
    toi = contact.edge_edge_ccd(ea0, ea1, eb0, eb1, ea0 + down, ea1 + down, eb0, eb1)
    assert 0.45 <= toi <= 0.5
    # parallel edges sliding past each other at a fixed 0.5 separation: no impact
    fa0, fa1 = np.array([0.0, 0, 0.5]), np.array([1.0, 0, 0.5])
    shift = np.array([3.0, 0, 0])
    assert contact.edge_edge_ccd(fa0, fa1, eb0, eb1, fa0 + shift, fa1 + shift, eb0, eb1) == 1.0


def test_point_edge_point_point(contact):
    toi = contact.point_edge_ccd(
        np.array([0.5, 1, 0]),
        np.zeros(3),
        np.array([1.0, 0, 0]),
        np.array([0.5, -1, 0]),
        np.zeros(3),
        np.array([1.0, 0, 0]),
    )
    assert 0.45 <= toi <= 0.5
    toi = contact.point_point_ccd(
        np.zeros(3), np.array([1.0, 0, 0]), np.array([1.0, 0, 0]), np.zeros(3)
    )  # head-on, meet at 0.5
    assert 0.45 <= toi <= 0.5


def dense_min_distance(f, x0, x1, t_end, n=150):
    ts = np.linspace(0.0, t_end, n)
    return min(f(*[(1 - t) * a + t * b for a, b in zip(x0, x1, strict=True)]) for t in ts)


@pytest.mark.parametrize("kind", ["point_triangle", "edge_edge"])
def test_random_trajectories_conservative_vs_tight_inclusion(contact, rng, kind):
    ccd = getattr(contact, f"{kind}_ccd")
    dist = getattr(contact, f"{kind}_distance")
    ti = ipctk.TightInclusionCCD(tolerance=1e-8, conservative_rescaling=1.0)
    ti_ccd = getattr(ti, f"{kind}_ccd")
    hits = 0
    for _ in range(300):
        x0 = [rng.uniform(-1, 1, 3) for _ in range(4)]
        x1 = [v + rng.normal(0, 1.5, 3) for v in x0]
        for xi in [0.0, 0.05]:
            if dist(*x0) <= xi**2:
                continue
            toi = ccd(*x0, *x1, min_distance=xi)
            # never beyond contact: every configuration up to toi is farther than xi
            assert dense_min_distance(dist, x0, x1, toi) > xi**2
            if xi > 0:
                continue
            hit, ti_toi = ti_ccd(*x0, *x1)
            if hit:
                hits += 1
                assert toi <= ti_toi + 1e-7
                assert toi >= 0.5 * ti_toi  # conservative, not useless
            if toi == 1.0:
                assert not hit or ti_toi >= 1.0 - 1e-6
    assert hits >= 15  # the sample really contains impacts


def test_ground_ccd(contact):
    toi = contact.point_ground_ccd(np.array([0, 0, 1.0]), np.array([0, 0, -1.0]), 0.0)
    assert toi == pytest.approx(0.9 * 0.5)
    toi = contact.point_ground_ccd(
        np.array([0, 0, 1.0]), np.array([0, 0, -1.0]), 0.2, min_distance=0.1
    )
    assert toi == pytest.approx(0.9 * 0.35)
    assert contact.point_ground_ccd(np.array([0, 0, 1.0]), np.array([0, 0, 2.0]), 0.0) == 1.0
    assert contact.point_ground_ccd(np.array([0, 0, 1.0]), np.array([0, 0, 0.5]), 0.0) == 1.0
    assert contact.point_ground_ccd(np.array([0, 0, -1.0]), np.array([0, 0, 2.0]), 0.0) == 0.0


@pytest.mark.parametrize("xi", [0.0, 0.05])
def test_moves_shorter_than_the_first_step_end_at_tmax(contact, rng, xi):
    # ACCD's first step is (1 − target) gap0 / l_p: a pair whose relative motion l_p stays
    # below 0.9 of its gap cannot lose 90% of it, so the whole move is safe (t = 1; the
    # solver's swept pairs are mostly such). Checked against dense sampling of the path.
    for _ in range(100):
        x0 = [rng.uniform(-1, 1, 3) for _ in range(4)]
        for kind in ("point_triangle", "edge_edge"):
            dist = getattr(contact, f"{kind}_distance")
            gap0 = np.sqrt(dist(*x0)) - xi
            if gap0 <= 1e-3:
                continue
            step = rng.normal(size=(4, 3))
            # each |Δx_i − mean| <= 2 max |Δx| <= 0.425 gap0: l_p <= 0.85 gap0
            step *= 0.85 * gap0 / (4 * np.abs(step).sum(axis=1).max())
            x1 = [a + d for a, d in zip(x0, step, strict=True)]
            toi = getattr(contact, f"{kind}_ccd")(*x0, *x1, min_distance=xi)
            assert toi == 1.0
            gaps = np.sqrt(dense_min_distance(dist, x0, x1, 1.0)) - xi
            assert gaps >= 0.1 * gap0
