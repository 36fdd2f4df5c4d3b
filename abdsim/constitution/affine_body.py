"""Affine-body constitutions: solids, shells (codim 2D) and rods (codim 1D).

``apply_to`` writes every attribute of the spec (``shared/seed/affine_body.txt``) with its exact
name, type and default.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np

from abdsim._native import _core
from abdsim.constitution.rigid_body import DyadicMass, _write_dyadic
from abdsim.geometry import validation as check
from abdsim.geometry.simplicial_complex import SimplicialComplex

#: Constitution UIDs of the spec.
CONSTITUTION_UIDS = {"OrthoPotential": 1, "ARAP": 2}
#: κ range the ABD paper recommends (Pa).
KAPPA_RANGE = (1e8, 1e11)


class ShapeEnergy(NamedTuple):
    """Value, gradient (12,) and Hessian (12, 12) of a shape energy."""

    value: float
    gradient: np.ndarray
    hessian: np.ndarray


def _positive_finite(what: str, value: float) -> float:
    v = float(value)
    if not (np.isfinite(v) and v > 0):
        raise ValueError(f"{what} must be positive and finite, got {value}")
    return v


class AffineBodyConstitution:
    """Affine body of a solid: a tet mesh or a closed, outward-oriented triangle surface.

    Args:
        name: ``"OrthoPotential"`` (uid 1, κ v̄ ‖AAᵀ−I‖²_F) or ``"ARAP"`` (uid 2, κ v̄ ‖A−R‖²_F).
    """

    def __init__(self, name: str = "OrthoPotential") -> None:
        if name not in CONSTITUTION_UIDS:
            raise ValueError(
                f"unknown constitution {name!r}; choose one of {list(CONSTITUTION_UIDS)}"
            )
        self.name = name
        self.uid = CONSTITUTION_UIDS[name]

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"

    # -- energy ---------------------------------------------------------------------------
    def energy(
        self,
        q: np.ndarray,
        kappa: float,
        volume: float,
        project_psd: bool = False,
        absorb: float = 0.0,
    ) -> ShapeEnergy:
        """Shape energy κ v̄ Ψ(A) at ``q = [p, a1, a2, a3]`` with gradient and Hessian.

        Args:
            project_psd: clamp the Hessian's negative eigenvalues to zero.
            absorb: with ``project_psd``, a lower bound on the smallest eigenvalue of the
                matrix the Hessian is added to (the simulator passes half the smallest
                eigenvalue of the body's mass matrix): the OrthoPotential's clamp is skipped
                when κ v̄ times a bound on its negative eigenvalues is within it, and the
                exact Hessian is returned (the sum stays positive definite).
        """
        qa = np.asarray(q, dtype=np.float64).reshape(-1)
        if qa.shape != (12,):
            raise ValueError(f"q must have 12 entries [p, a1, a2, a3], got shape {np.shape(q)}")
        if not np.isfinite(qa).all():
            raise ValueError("q contains NaN or infinite values")
        absorb = float(absorb)
        if not (np.isfinite(absorb) and absorb >= 0.0):
            raise ValueError(f"absorb must be finite and >= 0, got {absorb}")
        value, g, h = _core.shape_energy(
            self.uid, qa, float(kappa), float(volume), project_psd, absorb
        )
        return ShapeEnergy(float(value), np.asarray(g), np.asarray(h))

    # -- attributes -----------------------------------------------------------------------
    def apply_to(self, sc: SimplicialComplex, kappa: float, mass_density: float = 1e3) -> None:
        """Set the spec's meta and instance attributes on ``sc`` (every instance a body).

        Raises:
            ValueError: non-positive κ or density, an open / non-manifold / inconsistently
                oriented surface, or a non-positive volume.
        """
        check.check_mesh_arrays(sc)
        kappa = self._check_kappa(kappa)
        rho = _positive_finite("mass_density", mass_density)
        v = sc.positions
        if sc.dim == 3:
            dm = DyadicMass(*_core.tet_mesh_mass(v, sc.tetrahedra, rho))
        elif sc.dim == 2:
            check.check_nondegenerate_triangles(v, sc.triangles)
            check.check_closed_oriented(sc.triangles)
            dm = DyadicMass(*_core.closed_surface_mass(v, sc.triangles, rho))
            if dm.abd_mass < 0:
                raise ValueError(
                    "closed surface has negative volume: it is oriented inward (flip the "
                    "triangles' winding)"
                )
        else:
            raise ValueError(
                "an edge mesh has no volume: use AffineBodyRod for rods (AffineBodyShell for "
                "open surfaces)"
            )
        self._write(sc, kappa, rho, dm, dm.abd_mass / rho)

    def _check_kappa(self, kappa: float) -> float:
        k = _positive_finite("kappa", kappa)
        if not KAPPA_RANGE[0] <= k <= KAPPA_RANGE[1]:
            warnings.warn(
                f"kappa = {k:g} Pa is outside the recommended range [100 MPa, 100 GPa]",
                stacklevel=3,
            )
        return k

    def _write(
        self, sc: SimplicialComplex, kappa: float, rho: float, dm: DyadicMass, volume: float
    ) -> None:
        if not (volume > 0 and np.isfinite(volume)):
            raise ValueError(f"body volume must be positive, got {volume}")
        meta = sc.meta
        meta["constitution_uid"] = np.uint64(self.uid)
        meta["volume"] = np.float64(volume)
        meta["mass_density"] = np.float64(rho)
        _write_dyadic(sc, dm)
        if np.linalg.eigvalsh(np.asarray(_core.mass_matrix(*dm))).min() <= 0:
            raise ValueError("body has a singular mass matrix (degenerate geometry)")
        if "self_collision" not in meta:
            meta["self_collision"] = np.int32(0)
        meta["dof_offset"] = np.int32(-1)
        meta["dof_count"] = np.int32(12 * sc.instance_count)
        inst = sc.instances
        inst.create("kappa", np.float64(kappa))
        for key, default in (("is_fixed", 0), ("is_dynamic", 1), ("external_kinetic", 0)):
            if key not in inst:
                inst.create(key, np.int32(default))
        if "velocity" not in inst:
            inst.create("velocity", np.zeros((4, 4)))


class _CodimConstitution(AffineBodyConstitution):
    """Shared parts of shells and rods: a per-vertex thickness radius r."""

    def apply_to(  # type: ignore[override]
        self,
        sc: SimplicialComplex,
        kappa: float,
        mass_density: float = 1e3,
        thickness: float = 0.01,
    ) -> None:
        """Set the spec's attributes plus ``is_codim = 1`` and vertex ``thickness = r``.

        Raises:
            ValueError: the wrong kind of mesh, degenerate simplices, non-positive κ,
                density or thickness.
        """
        check.check_mesh_arrays(sc, thickness=False)  # apply_to writes the thickness
        self._check_mesh(sc)
        kappa = self._check_kappa(kappa)
        rho = _positive_finite("mass_density", mass_density)
        r = _positive_finite("thickness", thickness)
        sc.vertices.create("thickness", np.float64(r))
        sc.meta["is_codim"] = np.int32(1)
        dm, volume = self._mass(sc, np.asarray(sc.vertices["thickness"]), rho)
        self._write(sc, kappa, rho, dm, volume)

    def _check_mesh(self, sc: SimplicialComplex) -> None:
        raise NotImplementedError

    def _mass(self, sc: SimplicialComplex, r: np.ndarray, rho: float) -> tuple[DyadicMass, float]:
        raise NotImplementedError


class AffineBodyShell(_CodimConstitution):
    """Codim-2D affine body on a triangle mesh: a slab of full thickness 2r (v̄ = Σ Aᵢ·2r)."""

    def _check_mesh(self, sc: SimplicialComplex) -> None:
        if len(sc.triangles) == 0:
            raise ValueError("AffineBodyShell needs a triangle mesh")
        check.check_nondegenerate_triangles(sc.positions, sc.triangles)

    def _mass(self, sc: SimplicialComplex, r: np.ndarray, rho: float) -> tuple[DyadicMass, float]:
        dm = DyadicMass(*_core.shell_mass(sc.positions, sc.triangles, r, rho))
        areas = check.triangle_areas(sc.positions, sc.triangles)
        return dm, float(np.sum(areas * 2.0 * r[sc.triangles].mean(axis=1)))


class AffineBodyRod(_CodimConstitution):
    """Codim-1D affine body on an edge mesh: a cylinder of radius r (v̄ = Σ Lᵢ·πr²)."""

    def _check_mesh(self, sc: SimplicialComplex) -> None:
        if len(sc.edges) == 0:
            raise ValueError("AffineBodyRod needs an edge mesh")
        lengths = self._lengths(sc)
        scale = max(float(np.ptp(sc.positions, axis=0).max()), 1e-300)
        if (lengths <= 1e-14 * scale).any():
            raise ValueError(f"edge {int(np.argmax(lengths <= 1e-14 * scale))} has zero length")

    @staticmethod
    def _lengths(sc: SimplicialComplex) -> np.ndarray:
        p = sc.positions[sc.edges]
        return np.linalg.norm(p[:, 1] - p[:, 0], axis=1)

    def _mass(self, sc: SimplicialComplex, r: np.ndarray, rho: float) -> tuple[DyadicMass, float]:
        dm = DyadicMass(*_core.rod_mass(sc.positions, sc.edges, r, rho))
        r_edge = r[sc.edges].mean(axis=1)
        return dm, float(np.sum(self._lengths(sc) * np.pi * r_edge**2))
