"""Dyadic mass <-> rigid-body mass properties, and the 12x12 mass matrix of a body."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from abdsim._native import _core
from abdsim.geometry.simplicial_complex import SimplicialComplex


class RigidBody(NamedTuple):
    """Rigid-body view of a dyadic mass: mass, centre of mass and inertia about it."""

    mass: float
    mass_center: np.ndarray
    inertia: np.ndarray


class DyadicMass(NamedTuple):
    """ABD dyadic mass: m, m x̄ = ∫ρx̄, S = ∫ρx̄x̄ᵀ."""

    abd_mass: float
    abd_mass_x_bar: np.ndarray
    abd_mass_x_bar_x_bar: np.ndarray


def _dyadic_of(sc: SimplicialComplex) -> DyadicMass:
    if "abd_mass" not in sc.meta:
        raise ValueError(
            "geometry has no dyadic mass: apply a constitution (e.g. "
            "AffineBodyConstitution().apply_to(sc, kappa)) first"
        )
    return DyadicMass(
        float(sc.meta["abd_mass"]),
        np.asarray(sc.meta["abd_mass_x_bar"], dtype=np.float64),
        np.asarray(sc.meta["abd_mass_x_bar_x_bar"], dtype=np.float64),
    )


def mass_matrix(sc: SimplicialComplex) -> np.ndarray:
    """The 12x12 ABD mass matrix of ``sc``'s bodies (shared by all its instances)."""
    return np.asarray(_core.mass_matrix(*_dyadic_of(sc)))


def to_rigid_body(sc: SimplicialComplex) -> RigidBody:
    """Mass, centre of mass (rest frame) and inertia about the centre, from the dyadic mass."""
    m, c, inertia = _core.to_rigid_body(*_dyadic_of(sc))
    return RigidBody(float(m), np.asarray(c), np.asarray(inertia))


def from_rigid_body(mass: float, mass_center: np.ndarray, inertia: np.ndarray) -> DyadicMass:
    """Dyadic mass with exactly the given rigid-body mass properties.

    Raises:
        ValueError: if mass is not positive, or the inertia is not symmetric positive
            definite or violates the triangle inequality (not a physical body).
    """
    c = np.asarray(mass_center, dtype=np.float64).reshape(-1)
    inertia_m = np.asarray(inertia, dtype=np.float64)
    if c.shape != (3,) or inertia_m.shape != (3, 3):
        raise ValueError(
            f"mass_center must be (3,) and inertia (3, 3); got {c.shape} and {inertia_m.shape}"
        )
    if not (np.isfinite(mass) and mass > 0):
        raise ValueError(f"mass must be positive and finite, got {mass}")
    if not (np.isfinite(c).all() and np.isfinite(inertia_m).all()):
        raise ValueError("mass_center and inertia must be finite")
    check_inertia(inertia_m)
    m, mx, s = _core.from_rigid_body(float(mass), c, inertia_m)
    return DyadicMass(float(m), np.asarray(mx), np.asarray(s))


def check_inertia(inertia: np.ndarray, what: str = "inertia") -> None:
    """Raise ValueError unless ``inertia`` is a physical inertia tensor."""
    if not np.allclose(inertia, inertia.T, rtol=1e-9, atol=1e-12 * max(1.0, abs(inertia).max())):
        raise ValueError(f"{what} is not symmetric: {inertia.tolist()}")
    moments = np.linalg.eigvalsh(0.5 * (inertia + inertia.T))
    if moments.min() <= 0:
        raise ValueError(f"{what} is not positive definite (principal moments {moments.tolist()})")
    tol = 1e-9 * moments.max()
    a, b, c = moments
    if a + b < c - tol:
        raise ValueError(
            f"{what} violates the triangle inequality (principal moments {moments.tolist()})"
        )
    # On the triangle equality the second moment (a + b - c) / 2 along the largest moment's
    # axis is zero: all the mass lies in a plane, and an affine body's 12x12 mass matrix
    # (which holds the second moments) is singular.
    if a + b <= c + tol:
        raise ValueError(
            f"{what} puts all the mass in a plane (principal moments {moments.tolist()}: "
            "the two smaller sum to the largest); an affine body needs mass off every plane"
        )


def assign_rigid_body(
    sc: SimplicialComplex, mass: float, mass_center: np.ndarray, inertia: np.ndarray
) -> None:
    """Give ``sc``'s bodies exact rigid-body mass properties instead of a density.

    Overwrites the dyadic mass (and ``mass``, ``mass_center``, ``inertia``) in ``sc.meta``;
    ``mass_density`` becomes the equivalent mass / volume. Call after ``apply_to``.
    """
    if "volume" not in sc.meta:
        raise ValueError("apply a constitution before assigning rigid-body mass properties")
    dm = from_rigid_body(mass, mass_center, inertia)
    _write_dyadic(sc, dm)
    sc.meta["mass_density"] = np.float64(dm.abd_mass / float(sc.meta["volume"]))


def _write_dyadic(sc: SimplicialComplex, dm: DyadicMass) -> None:
    sc.meta["abd_mass"] = np.float64(dm.abd_mass)
    sc.meta["abd_mass_x_bar"] = dm.abd_mass_x_bar
    sc.meta["abd_mass_x_bar_x_bar"] = dm.abd_mass_x_bar_x_bar
    rb = to_rigid_body(sc)
    sc.meta["mass"] = np.float64(rb.mass)
    sc.meta["mass_center"] = rb.mass_center
    sc.meta["inertia"] = rb.inertia
