"""Helpers for the solver tests: boxes with a constitution, rigid-motion velocities and
angular momentum computed independently of the solver (from A, Ȧ and the dyadic mass)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import abdsim

EXTENTS = (0.4, 0.2, 0.1)  # distinct principal moments: I_x < I_y < I_z


def skew(w: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def unskew(W: np.ndarray) -> np.ndarray:
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


def make_box(
    n: int = 1,
    extents=EXTENTS,
    constitution: str = "OrthoPotential",
    kappa: float = 1e8,
    offset=(0.0, 0.0, 0.0),
) -> abdsim.SimplicialComplex:
    """n instances of a box, its rest mesh shifted by `offset` (so the centre of mass is
    not at the body origin when offset != 0)."""
    sc = abdsim.geometry.box(extents)
    if np.any(offset):
        sc = abdsim.geometry.triangle_mesh(sc.positions + np.asarray(offset), sc.triangles)
    sc.instances.resize(n)
    abdsim.AffineBodyConstitution(constitution).apply_to(sc, kappa=kappa)
    return sc


def rigid_velocity(A: np.ndarray, omega: np.ndarray, v: np.ndarray) -> np.ndarray:
    """dT/dt of a body with rotation A, angular velocity omega (world) and velocity v of p."""
    V = np.zeros((4, 4))
    V[:3, :3] = skew(omega) @ A
    V[:3, 3] = v
    return V


def angular_momentum(world: abdsim.World, sc: abdsim.SimplicialComplex) -> np.ndarray:
    """L = ∫ρ x × ẋ about the world origin for every body of `sc` (n, 3), with
    x = A x̄ + p: L = m p × ṗ + p × (Ȧ m x̄) + (A m x̄) × ṗ + vec(skew part of A S Ȧᵀ)."""
    m = float(sc.meta["abd_mass"])
    mx = np.asarray(sc.meta["abd_mass_x_bar"])
    S = np.asarray(sc.meta["abd_mass_x_bar_x_bar"])
    T, V = world.transforms(), world.velocities()
    A, Ad, p, pd = T[:, :3, :3], V[:, :3, :3], T[:, :3, 3], V[:, :3, 3]
    M = A @ S @ np.transpose(Ad, (0, 2, 1))
    L_rot = np.stack([M[:, 1, 2] - M[:, 2, 1], M[:, 2, 0] - M[:, 0, 2], M[:, 0, 1] - M[:, 1, 0]], 1)
    return (
        m * np.cross(p, pd)
        + np.cross(p, np.einsum("kij,j->ki", Ad, mx))
        + np.cross(np.einsum("kij,j->ki", A, mx), pd)
        + L_rot
    )


def random_rotations(rng: np.random.Generator, n: int) -> np.ndarray:
    """n uniformly random proper rotations, (n, 3, 3)."""
    q, r = np.linalg.qr(rng.normal(size=(n, 3, 3)))
    q = q * np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1
    return q


def world_of(*geometries: abdsim.SimplicialComplex, **settings) -> abdsim.World:
    """A World of the given geometries (settings as for abdsim.Scene)."""
    scene = abdsim.Scene(**settings)
    for sc in geometries:
        scene.add(sc)
    return abdsim.World(scene)


@pytest.fixture
def tools() -> SimpleNamespace:
    """The helpers above (tests import the installed package, not this folder)."""
    return SimpleNamespace(
        make_box=make_box,
        skew=skew,
        unskew=unskew,
        rigid_velocity=rigid_velocity,
        angular_momentum=angular_momentum,
        random_rotations=random_rotations,
        world_of=world_of,
        EXTENTS=EXTENTS,
    )
