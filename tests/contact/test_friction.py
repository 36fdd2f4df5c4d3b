"""Lagged friction pieces: C¹ mollifier, tangent bases, closest points, per-stencil potential."""

import ipctk
import numpy as np
import pytest

EPS = 1e-3 * 0.01  # ε_v h for ε_v = 1e-3 m/s, h = 0.01 s


def test_mollifier_closed_form_and_ipctk(contact):
    for y in np.concatenate([np.linspace(0, 2 * EPS, 41), [1.0]]):
        if y < EPS:
            f0 = -(y**3) / (3 * EPS**2) + y**2 / EPS + EPS / 3
            f1 = -(y**2) / EPS**2 + 2 * y / EPS
            f2 = -2 * y / EPS**2 + 2 / EPS
        else:
            f0, f1, f2 = y, 1.0, 0.0
        assert contact.smooth_friction_f0(y, EPS) == pytest.approx(f0, rel=1e-12)
        assert contact.smooth_friction_f1(y, EPS) == pytest.approx(f1, rel=1e-12, abs=1e-15)
        assert contact.smooth_friction_f2(y, EPS) == pytest.approx(f2, rel=1e-12, abs=1e-15)
        assert contact.smooth_friction_f0(y, EPS) == pytest.approx(ipctk.smooth_friction_f0(y, EPS))
        assert contact.smooth_friction_f1(y, EPS) == pytest.approx(ipctk.smooth_friction_f1(y, EPS))
        if y > 0:
            assert contact.smooth_friction_f1_over_x(y, EPS) == pytest.approx(f1 / y, rel=1e-12)
            assert contact.smooth_friction_f2_x_minus_f1_over_x3(y, EPS) == pytest.approx(
                (f2 * y - f1) / y**3, rel=1e-9
            )
            assert contact.smooth_friction_f2_x_minus_f1_over_x3(y, EPS) == pytest.approx(
                ipctk.smooth_friction_f2_x_minus_f1_over_x3(y, EPS), rel=1e-9
            )
    # derivatives by finite differences, C¹ across ε
    for y in [0.3 * EPS, 0.9 * EPS, 1.5 * EPS]:
        h = 1e-6 * EPS
        f0, f1 = contact.smooth_friction_f0, contact.smooth_friction_f1
        fd1 = (f0(y + h, EPS) - f0(y - h, EPS)) / (2 * h)
        fd2 = (f1(y + h, EPS) - f1(y - h, EPS)) / (2 * h)
        assert contact.smooth_friction_f1(y, EPS) == pytest.approx(fd1, rel=1e-6)
        assert contact.smooth_friction_f2(y, EPS) == pytest.approx(fd2, rel=1e-5, abs=1e-3 / EPS)
    below = contact.smooth_friction_f0(EPS * (1 - 1e-12), EPS)
    assert below == pytest.approx(EPS, rel=1e-9)
    assert contact.smooth_friction_f1(EPS * (1 - 1e-12), EPS) == pytest.approx(1.0, rel=1e-9)


def projector(T):
    return T @ T.T


def test_tangent_bases_span_ipctk_planes(contact, rng):
    for _ in range(20):
        v = [rng.uniform(-1, 1, 3) for _ in range(4)]
        pairs = [
            ("point_point", v[:2]),
            ("point_edge", v[:3]),
            ("point_triangle", v),
            ("edge_edge", v),
        ]
        for name, args in pairs:
            T = getattr(contact, f"{name}_tangent_basis")(*args)
            Tref = getattr(ipctk, f"{name}_tangent_basis")(*args)
            np.testing.assert_allclose(T.T @ T, np.eye(2), atol=1e-12)
            np.testing.assert_allclose(projector(T), projector(Tref), atol=1e-10, err_msg=name)
    np.testing.assert_allclose(contact.ground_tangent_basis(), np.eye(3)[:, :2])


def test_closest_points_match_ipctk(contact, rng):
    for _ in range(20):
        v = [rng.uniform(-1, 1, 3) for _ in range(4)]
        assert contact.point_edge_closest_point(*v[:3]) == pytest.approx(
            ipctk.point_edge_closest_point(*v[:3]), rel=1e-10
        )
        np.testing.assert_allclose(
            contact.point_triangle_closest_point(*v),
            ipctk.point_triangle_closest_point(*v),
            rtol=1e-10,
        )
        np.testing.assert_allclose(
            contact.edge_edge_closest_point(*v), ipctk.edge_edge_closest_point(*v), rtol=1e-9
        )


@pytest.mark.parametrize("scale", [0.3, 3.0])  # sticking (|u| < ε) and sliding regimes
def test_friction_potential_derivatives(contact, fd, rng, scale):
    mu_lambda = 2.5
    for nv in [1, 2, 3, 4]:
        for _ in range(5):
            w = rng.uniform(-1, 1, nv)
            T = np.linalg.qr(rng.normal(size=(3, 2)))[0]
            dx = rng.normal(size=3 * nv)
            u = T.T @ sum(w[i] * dx[3 * i : 3 * i + 3] for i in range(nv))
            dx *= scale * EPS / np.linalg.norm(u)  # |u| = scale ε
            value, grad, hess = contact.friction_potential(dx, w, T, mu_lambda, EPS)
            y = scale * EPS
            assert value == pytest.approx(mu_lambda * contact.smooth_friction_f0(y, EPS), rel=1e-9)

            def potential(z, k, w=w, T=T):
                return contact.friction_potential(z, w, T, mu_lambda, EPS)[k]

            h = 1e-4 * EPS
            np.testing.assert_allclose(
                grad, fd.gradient(lambda z: potential(z, 0), dx, h), rtol=1e-5, atol=1e-6
            )
            np.testing.assert_allclose(
                hess,
                fd.jacobian(lambda z: potential(z, 1), dx, h),
                rtol=1e-5,
                atol=1e-5 * np.abs(hess).max(),
            )
            assert np.linalg.eigvalsh(hess).min() >= -1e-9 * np.abs(hess).max()
            # sliding: the force on the stencil has magnitude μλ along −u (in the tangent plane)
            if scale > 1:
                Gamma = np.hstack([w[i] * T.T for i in range(nv)])
                force = np.linalg.lstsq(Gamma.T, grad, rcond=None)[0]
                assert np.linalg.norm(force) == pytest.approx(mu_lambda, rel=1e-9)


@pytest.mark.parametrize("scale", [0.3, 3.0, 100.0])  # sticking, sliding, fast sliding
def test_friction_majorizing_model_bounds_the_potential_from_above(contact, rng, scale):
    """The majorising Hessian (f1/|u| I across and along u) makes the quadratic model an upper
    bound of the potential along any step, steps that stop and reverse the slide included,
    where the exact model (linear along a sliding u) falls below it by up to 2 μλ times the
    overshoot."""
    mu_lambda, worst_exact = 2.5, 0.0
    for nv in [1, 2, 4]:
        w = rng.uniform(-1, 1, nv)
        T = np.linalg.qr(rng.normal(size=(3, 2)))[0]
        Gamma = np.hstack([w[i] * T.T for i in range(nv)])
        dx = rng.normal(size=3 * nv)
        dx *= scale * EPS / np.linalg.norm(Gamma @ dx)
        value, grad, hess = contact.friction_potential(dx, w, T, mu_lambda, EPS, majorize=True)
        _, grad_exact, hess_exact = contact.friction_potential(dx, w, T, mu_lambda, EPS)
        np.testing.assert_array_equal(grad, grad_exact)
        assert np.linalg.eigvalsh(hess - hess_exact).min() >= -1e-9 * np.abs(hess).max()
        for t in np.linspace(-3.0, 3.0, 61):  # t = -1: the slide stopped, -2: reversed
            for step in (dx, rng.normal(size=3 * nv) * scale * EPS):
                actual = contact.friction_potential(dx + t * step, w, T, mu_lambda, EPS)[0]
                model = value + t * grad @ step + 0.5 * t * t * step @ hess @ step
                exact = value + t * grad @ step + 0.5 * t * t * step @ hess_exact @ step
                assert actual <= model + 1e-12 * mu_lambda * EPS * (1 + scale)
                worst_exact = max(worst_exact, (actual - exact) / (mu_lambda * scale * EPS))
    if scale > 1:  # the exact model misses the reversal: 2 μλ |u| at t = -2 (relative: 2)
        assert worst_exact > 1.5


def test_friction_potential_at_rest(contact):
    T = np.eye(3)[:, :2]
    value, grad, hess = contact.friction_potential(np.zeros(3), np.ones(1), T, 2.0, EPS)
    assert value == pytest.approx(2.0 * EPS / 3)
    np.testing.assert_allclose(grad, 0)
    np.testing.assert_allclose(hess, 2.0 * 2 / EPS * np.diag([1.0, 1.0, 0.0]))
