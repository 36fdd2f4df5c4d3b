import numpy as np
import pytest

import abdsim


def test_from_rigid_body_diagonal_formula():
    ix, iy, iz = 2.0, 3.0, 4.0
    dm = abdsim.from_rigid_body(5.0, np.zeros(3), np.diag([ix, iy, iz]))
    expected = np.diag([(-ix + iy + iz) / 2, (ix - iy + iz) / 2, (ix + iy - iz) / 2])
    np.testing.assert_allclose(dm.abd_mass_x_bar_x_bar, expected, rtol=1e-15)
    assert dm.abd_mass == 5.0
    np.testing.assert_array_equal(dm.abd_mass_x_bar, np.zeros(3))


def test_round_trip_random_bodies(rng):
    for _ in range(20):
        r, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        moments = np.sort(rng.uniform(0.5, 2.0, size=3))
        # strict triangle inequality: on the equality the mass lies in a plane (singular mass)
        moments[2] = min(moments[2], 0.99 * (moments[0] + moments[1]))
        inertia = r @ np.diag(moments) @ r.T
        m = rng.uniform(0.1, 10)
        c = rng.normal(size=3)
        sc = abdsim.geometry.box(1.0)
        abdsim.AffineBodyConstitution().apply_to(sc, kappa=1e8)
        abdsim.assign_rigid_body(sc, m, c, inertia)
        rb = abdsim.to_rigid_body(sc)
        assert rb.mass == pytest.approx(m, rel=1e-14)
        np.testing.assert_allclose(rb.mass_center, c, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(rb.inertia, inertia, rtol=1e-10, atol=1e-12)
        assert sc.meta["mass_density"] == pytest.approx(m / sc.meta["volume"])
        np.linalg.cholesky(abdsim.mass_matrix(sc))


def test_to_then_from_rigid_body_recovers_dyadic_mass():
    sc = abdsim.geometry.capsule(0.1, 0.3)
    abdsim.AffineBodyConstitution().apply_to(sc, kappa=1e8, mass_density=800.0)
    rb = abdsim.to_rigid_body(sc)
    dm = abdsim.from_rigid_body(*rb)
    np.testing.assert_allclose(
        dm.abd_mass_x_bar_x_bar, sc.meta["abd_mass_x_bar_x_bar"], rtol=1e-10, atol=1e-14
    )
    np.testing.assert_allclose(dm.abd_mass_x_bar, sc.meta["abd_mass_x_bar"], atol=1e-15)


@pytest.mark.parametrize(
    "mass, inertia, message",
    [
        (0.0, np.eye(3), "mass must be positive"),
        (-1.0, np.eye(3), "mass must be positive"),
        (1.0, np.diag([1.0, 1.0, -1.0]), "not positive definite"),
        (1.0, np.diag([1.0, 1.0, 3.0]), "triangle inequality"),
        (1.0, np.array([[1.0, 0.5, 0], [0, 1, 0], [0, 0, 1]]), "not symmetric"),
        (1.0, np.eye(2), "inertia"),
        (np.nan, np.eye(3), "mass must be positive"),
    ],
)
def test_non_physical_rigid_body_raises(mass, inertia, message):
    with pytest.raises(ValueError, match=message):
        abdsim.from_rigid_body(mass, np.zeros(3), inertia)


def test_an_inertia_with_all_mass_in_a_plane_is_refused():
    """Principal moments on the triangle equality (a + b = c: a lamina) leave a zero second
    moment, so the 12x12 mass matrix would be singular: a clear error, not a failed World."""
    r, _ = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))
    sc = abdsim.geometry.box(1.0)
    abdsim.AffineBodyConstitution().apply_to(sc, kappa=1e8)
    with pytest.raises(ValueError, match="all the mass in a plane"):
        abdsim.assign_rigid_body(sc, 1.0, np.zeros(3), r @ np.diag([0.01, 0.02, 0.03]) @ r.T)
    abdsim.assign_rigid_body(sc, 1.0, np.zeros(3), np.diag([0.01, 0.02, 0.0299]))  # just inside
    np.linalg.cholesky(abdsim.mass_matrix(sc))
