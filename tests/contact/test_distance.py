"""Squared distances, their types, gradients and Hessians: vs ipctk and finite differences."""

import ipctk
import numpy as np
import pytest


def split(x, n):
    return [x[3 * i : 3 * i + 3] for i in range(n)]


STENCILS = {
    # name: (number of vertices, abdsim function stem, ipctk stem, type enum name)
    "point_edge": (3, "point_edge", "PointEdgeDistanceType"),
    "point_triangle": (4, "point_triangle", "PointTriangleDistanceType"),
    "edge_edge": (4, "edge_edge", "EdgeEdgeDistanceType"),
}


def random_configs(rng, n_vertices, count, scale=1.0):
    return [rng.uniform(-scale, scale, 3 * n_vertices) for _ in range(count)]


@pytest.mark.parametrize("name", list(STENCILS))
def test_distance_matches_ipctk(contact, rng, name):
    nv, stem, enum = STENCILS[name]
    ours = getattr(contact, f"{stem}_distance")
    ours_g = getattr(contact, f"{stem}_distance_gradient")
    ours_h = getattr(contact, f"{stem}_distance_hessian")
    ours_t = getattr(contact, f"{stem}_distance_type")
    theirs = getattr(ipctk, f"{stem}_distance")
    theirs_g = getattr(ipctk, f"{stem}_distance_gradient")
    theirs_h = getattr(ipctk, f"{stem}_distance_hessian")
    theirs_t = getattr(ipctk, f"{stem}_distance_type")
    types_seen = set()
    for x in random_configs(rng, nv, 300):
        v = split(x, nv)
        t_ours, t_theirs = ours_t(*v), theirs_t(*v)
        assert int(t_ours) == int(t_theirs), (name, x)
        types_seen.add(int(t_ours))
        d = theirs(*v)
        assert ours(*v) == pytest.approx(d, rel=1e-10, abs=1e-14)
        np.testing.assert_allclose(ours_g(*v), theirs_g(*v), rtol=1e-8, atol=1e-10)
        np.testing.assert_allclose(ours_h(*v), theirs_h(*v), rtol=1e-7, atol=1e-8)
    # the random sample exercises every smooth piece
    n_types = len(getattr(contact, enum).__members__) - 1  # minus AUTO
    assert len(types_seen) == n_types, sorted(types_seen)


@pytest.mark.parametrize("name", list(STENCILS))
def test_every_piece_gradient_hessian_vs_finite_differences(contact, fd, rng, name):
    nv, stem, enum = STENCILS[name]
    f = getattr(contact, f"{stem}_distance")
    g = getattr(contact, f"{stem}_distance_gradient")
    h = getattr(contact, f"{stem}_distance_hessian")
    for dtype_name, dtype in getattr(contact, enum).__members__.items():
        for x in random_configs(rng, nv, 5):
            grad = g(*split(x, nv), dtype)
            hess = h(*split(x, nv), dtype)
            grad_fd = fd.gradient(lambda y, t=dtype: f(*split(y, nv), t), x)
            hess_fd = fd.jacobian(lambda y, t=dtype: g(*split(y, nv), t), x)
            np.testing.assert_allclose(grad, grad_fd, rtol=1e-6, atol=1e-7, err_msg=dtype_name)
            np.testing.assert_allclose(hess, hess_fd, rtol=1e-5, atol=1e-6, err_msg=dtype_name)
            np.testing.assert_allclose(hess, hess.T, atol=1e-12)


def test_point_point(contact, fd, rng):
    for _ in range(10):
        x = rng.uniform(-1, 1, 6)
        p0, p1 = x[:3], x[3:]
        assert contact.point_point_distance(p0, p1) == pytest.approx(np.sum((p0 - p1) ** 2))
        np.testing.assert_allclose(
            contact.point_point_distance_gradient(p0, p1),
            ipctk.point_point_distance_gradient(p0, p1),
        )
        np.testing.assert_allclose(
            contact.point_point_distance_hessian(p0, p1), ipctk.point_point_distance_hessian(p0, p1)
        )


def test_known_values(contact):
    t0, t1, t2 = np.zeros(3), np.array([1.0, 0, 0]), np.array([0.0, 1, 0])
    # above the interior: the height squared
    p = np.array([0.2, 0.3, 0.7])
    assert contact.point_triangle_distance(p, t0, t1, t2) == pytest.approx(0.49)
    assert contact.point_triangle_distance_type(p, t0, t1, t2).name == "P_T"
    # beyond vertex t1 along x: the distance to t1
    p = np.array([2.0, -0.5, 0.0])
    assert contact.point_triangle_distance(p, t0, t1, t2) == pytest.approx(1.0 + 0.25)
    assert contact.point_triangle_distance_type(p, t0, t1, t2).name == "P_T1"
    # outside the hypotenuse, in plane: distance to the line x + y = 1
    p = np.array([1.0, 1.0, 0.0])
    assert contact.point_triangle_distance(p, t0, t1, t2) == pytest.approx(0.5)
    assert contact.point_triangle_distance_type(p, t0, t1, t2).name == "P_E1"
    # crossing edges one unit apart
    ea0, ea1 = np.array([-1.0, 0, 0]), np.array([1.0, 0, 0])
    eb0, eb1 = np.array([0.0, -1, 1]), np.array([0.0, 1, 1])
    assert contact.edge_edge_distance(ea0, ea1, eb0, eb1) == pytest.approx(1.0)
    assert contact.edge_edge_distance_type(ea0, ea1, eb0, eb1).name == "EA_EB"


def test_parallel_edges_avoid_line_line_piece(contact):
    ea0, ea1 = np.array([0.0, 0, 0]), np.array([1.0, 0, 0])
    for eps in [0.0, 1e-13, 1e-11]:
        eb0, eb1 = np.array([0.3, 0.2, 0.1]), np.array([1.7, 0.2, 0.1 + eps])
        dtype = contact.edge_edge_distance_type(ea0, ea1, eb0, eb1)
        d = contact.edge_edge_distance(ea0, ea1, eb0, eb1)
        assert d == pytest.approx(0.05, rel=1e-9)
        assert d == pytest.approx(ipctk.edge_edge_distance(ea0, ea1, eb0, eb1), rel=1e-9)
        if eps == 0.0:
            assert dtype.name != "EA_EB"


def test_mollifier_matches_ipctk_and_finite_differences(contact, fd, rng):
    for _ in range(30):
        x = rng.uniform(-1, 1, 12)
        # make the edges nearly parallel half of the time so the mollifier is active
        if rng.uniform() < 0.5:
            x[9:12] = x[6:9] + (x[3:6] - x[0:3]) * 0.7 + rng.normal(0, 1e-3, 3)
        v = split(x, 4)
        rest = split(rng.uniform(-1, 1, 12), 4)
        eps_x = contact.edge_edge_mollifier_threshold(*rest)
        assert eps_x == pytest.approx(ipctk.edge_edge_mollifier_threshold(*rest), rel=1e-12)
        c = contact.edge_edge_cross_squarednorm(*v)
        assert c == pytest.approx(ipctk.edge_edge_cross_squarednorm(*v), rel=1e-12)
        np.testing.assert_allclose(
            contact.edge_edge_cross_squarednorm_gradient(*v),
            ipctk.edge_edge_cross_squarednorm_gradient(*v),
            rtol=1e-10,
            atol=1e-12,
        )
        np.testing.assert_allclose(
            contact.edge_edge_cross_squarednorm_hessian(*v),
            ipctk.edge_edge_cross_squarednorm_hessian(*v),
            rtol=1e-10,
            atol=1e-12,
        )
        value, grad, hess = contact.edge_edge_mollifier_derivatives(*v, eps_x)
        assert value == pytest.approx(ipctk.edge_edge_mollifier(*v, eps_x), rel=1e-12)
        np.testing.assert_allclose(
            grad, ipctk.edge_edge_mollifier_gradient(*v, eps_x), rtol=1e-9, atol=1e-12
        )
        np.testing.assert_allclose(
            hess, ipctk.edge_edge_mollifier_hessian(*v, eps_x), rtol=1e-9, atol=1e-10
        )
        if value < 1.0:

            def mollifier(y, k, e=eps_x):
                return contact.edge_edge_mollifier_derivatives(*split(y, 4), e)[k]

            np.testing.assert_allclose(
                grad, fd.gradient(lambda y: mollifier(y, 0), x, 1e-7), rtol=1e-5, atol=1e-6
            )
            np.testing.assert_allclose(
                hess, fd.jacobian(lambda y: mollifier(y, 1), x, 1e-7), rtol=1e-4, atol=1e-5
            )


def test_mollifier_scalar(contact):
    eps = 0.3
    for c in [0.0, 0.1, 0.29, 0.3, 1.0]:
        expected = (2 - c / eps) * c / eps if c < eps else 1.0
        assert contact.edge_edge_mollifier(c, eps) == pytest.approx(expected)
        assert contact.edge_edge_mollifier(c, eps) == pytest.approx(
            ipctk.edge_edge_mollifier(c, eps)
        )
    # C¹ at the threshold: derivative from below tends to 0
    assert contact.edge_edge_mollifier_derivative(eps * (1 - 1e-9), eps) == pytest.approx(
        0, abs=1e-7
    )
