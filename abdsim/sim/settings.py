"""All settings of a simulation, in one dataclass (the Scene owns one)."""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields
from typing import Literal

import numpy as np

from abdsim._native import _core

_INTEGRATORS = {"bdf1": _core.Integrator.BDF1, "bdf2": _core.Integrator.BDF2}
_LINEAR_SOLVERS = {
    "auto": _core.LinearSolver.AUTO,
    "direct": _core.LinearSolver.DIRECT,
    "pcg": _core.LinearSolver.PCG,
}


# The type each setting must have (checked by SceneSettings.validate).
_KINDS: dict[str, type] = {
    "dt": float,
    "gravity": tuple,
    "integrator": str,
    "newton_tol_translation": float,
    "newton_tol_affine": float,
    "newton_max_iterations": int,
    "line_search_max_iterations": int,
    "armijo_c": float,
    "ccd_safety": float,
    "linear_solver": str,
    "direct_max_dofs": int,
    "pcg_tolerance": float,
    "pcg_max_iterations": int,
    "project_psd": bool,
    "energies": bool,
    "num_threads": int,
    "history_limit": int,
    "contact": bool,
    "d_hat": float,
    "contact_stiffness": float,
    "friction": float,
    "eps_v": float,
    "friction_iterations": int,
    "contact_damping": float,
    "restitution": (float, type(None)),
    "restitution_threshold": float,
    "kinematic_drive_stiffness": float,
}
_KIND_NAMES = {
    bool: "a bool (True or False)",
    str: "a string",
    int: "an integer",
    float: "a real number",
    tuple: "a sequence of 3 real numbers",
    (float, type(None)): "a real number or None",
}


@dataclass
class SceneSettings:
    """Time stepping and solver settings (SI units).

    Time stepping:
        dt: time step h (s).
        gravity: acceleration (m/s²), acting on the translation p of every body.
        integrator: ``"bdf1"`` (implicit Euler: robust, dissipative) or ``"bdf2"`` (second
            order, much less numerical damping; its first step is a BDF1 step).

    Newton (projected Newton on the incremental potential Π, ABD_NOTES §6):
        newton_tol_translation: stop when every body's last step |Δp|∞ ≤ this · dt (m/s).
        newton_tol_affine: ... and every |ΔA|∞ ≤ this · dt (1/s). A step counts only when
            the line search took it whole (a shortened step says Newton's model is off), and
            the converged step is still applied, so what is left is of second order in these
            numbers (free flight: AAᵀ stays within ~1e-7 of I; a tumbling box at dt = 0.01
            keeps its angular-momentum direction to 0.56° (BDF1) / 0.04° (BDF2) over 0.5 s).
        newton_max_iterations: Newton iterations before a step fails with SolverError
            (free flight needs 1-3; contact steps where bodies settle on edges and corners
            can take tens).
        line_search_max_iterations: halvings of the backtracking (Armijo) line search.
        armijo_c: sufficient-decrease constant of the line search.
        ccd_safety: a step bounded by an energy term's ``max_step`` (CCD) is taken to this
            fraction of the bound (IPC's 0.8).

    Linear solver:
        linear_solver: ``"auto"``: bodies that no energy term couples are solved per body (a
            12x12 Cholesky each; with no extra term every body runs its own Newton solve);
            coupled systems use the sparse direct solver (a block LDLᵀ over the bodies) up to
            ``direct_max_dofs`` unknowns and PCG with a 12x12 block-Jacobi preconditioner
            above. ``"direct"`` / ``"pcg"`` force one (on the global Newton system).
        direct_max_dofs: size limit (12 per body) of the direct solver under ``"auto"``.
        pcg_tolerance: relative residual at which PCG stops.
        pcg_max_iterations: PCG iterations before a step fails.

    Contact (IPC, ABD_NOTES §7; see ``Scene.add_ground`` and ``Scene.contact_table``):
        contact: enable contact between the bodies' surfaces (and the ground, if added). It is
            built only when there is something to collide: two bodies with surfaces, a ground,
            or a body with meta ``self_collision = 1``.
        d_hat: barrier activation distance d̂ (m): surfaces closer than d̂ (beyond their
            ``thickness``) repel; resting gaps end up in (0, d̂].
        contact_stiffness: barrier stiffness κ (N/m³; the term's κ, = IPC's κ / h²);
            0: IPC's adaptive stiffness, changed only when it cannot add energy: at a step
            that starts with no pair inside d̂ it is balanced against the rest of Π's
            gradient, clamped to [κ_min, 100 κ_min] (κ_min measured against 1e3 d̂, so it
            does not depend on the scene's size), and doubled while a gap keeps closing
            below 1e-9 × scene size; while pairs are compressed it stays, unless a gap
            shrinks below 1e-2 d̂ (a load far above the one it was chosen for). A state that
            starts with pairs inside d̂ (bodies placed resting on each other) gets the κ
            that makes it an equilibrium, so nothing jumps.
        friction: default Coulomb coefficient μ of every pair (0: frictionless); per pair in
            ``Scene.contact_table``, with the ground in ``Scene.add_ground``.
        contact_damping: damping ratio ζ ≥ 0 of every contact pair's normal motion (per pair in
            ``Scene.contact_table``, with the ground in ``Scene.add_ground``); 0 (default):
            none, today's behaviour. Each pair inside d̂ gets a dashpot C = 2 ζ √(k m) on its
            normal relative velocity, k the barrier's normal stiffness at the pair's gap and
            m the pair's (reduced) mass shared among its pairs: ζ = 1 is critically damped,
            MuJoCo's default ``solref`` damping ratio. It is a lagged convex term of the
            incremental potential (it can only remove energy; barrier and CCD are untouched).
            Alone it can only lower the restitution the integrator gives undamped (a box or a
            sphere dropped 5 cm: e ≤ 0.05 with BDF1, e ≈ 0.2-0.3 with BDF2); ζ = 1 takes it to
            0, like MuJoCo's default contact (the MJCF loader maps ``solref``'s damping
            ratio here). Dampers are lagged at the step start: the step that reaches the
            surface is the barrier's alone. For a given e use ``restitution``.
        restitution: coefficient of restitution e in [0, 1] of every contact pair (per pair
            in ``Scene.contact_table``); None (default): none, the integrator's own. A pair
            that comes within d̂ faster than ``restitution_threshold`` keeps its normal
            energy (relative normal kinetic energy at the contact point, barrier energy and
            gravity's work) at ½ m v_in² while it approaches and at e² of that once it
            separates, by impulses along the normal after each step (Stronge's energetic
            law): it leaves at e v_in, and the integrator's own loss inside the barrier is
            given back. Velocities only change, positions never (no intersection);
            docs/restitution.md says why and what it achieves.
        restitution_threshold: approach speed (m/s) below which an impact is inelastic, left
            to the integrator (as Box2D's and PhysX's bounce thresholds): resting and slowly
            touching bodies keep BDF's damping and come to rest.
        eps_v: friction smoothing speed ε_v (m/s): "static" friction creeps at a fraction of
            this speed (lagged IPC friction).
        friction_iterations: IPC's friction iterations: after Newton converges, friction's
            normal forces and tangent bases (lagged at the step start) are evaluated again at
            the solution and Newton goes on, this many times per step (0: lagged once, so a
            body that starts a step compressed in the barrier brakes with a transient force).
            Under BDF2 friction measures sliding from the integrator's history point q̂.
        kinematic_drive_stiffness: a kinematic body whose scripted move would cross contact
            is, for that step, not placed at its target but driven there by
            s (½ (x − target)ᵀ M (x − target) + h² Ψ), i.e. as the same body s times heavier
            and stiffer heading for the target (s this ratio, M its mass matrix, Ψ its shape
            energy; s = 1e4 at h = 0.01 s makes a 1 kg link a 1e8 N/m spring). It stops
            short of what it would cross and pushes what it meets; the distance left is
            ``StepDiagnostics.kinematic_lag``.

    Other:
        project_psd: project the shape-energy Hessian to PSD (leave on).
        energies: evaluate Π and its parts at the end of every step into
            ``StepDiagnostics.energies`` (MuJoCo's ``mjENBL_ENERGY``). Off: ``energies`` is
            empty and a step skips that evaluation (about 0.3 us of a Panda's ~12 us step);
            the motion is the same to the bit. They cannot be evaluated later from the history
            (a term's value depends on its state at that step).
        num_threads: worker threads (0: all hardware threads). Results are bit-identical for any
            number of threads.
        history_limit: per-step diagnostics kept in ``World.history`` (0: none).
    """

    dt: float = 0.01
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    integrator: Literal["bdf1", "bdf2"] = "bdf1"
    newton_tol_translation: float = 0.01
    newton_tol_affine: float = 0.1
    newton_max_iterations: int = 200
    line_search_max_iterations: int = 40
    armijo_c: float = 1e-4
    ccd_safety: float = 0.8
    linear_solver: Literal["auto", "direct", "pcg"] = "auto"
    direct_max_dofs: int = 12000
    pcg_tolerance: float = 1e-8
    pcg_max_iterations: int = 2000
    project_psd: bool = True
    energies: bool = True
    num_threads: int = 0
    history_limit: int = 10000
    contact: bool = True
    d_hat: float = 1e-3
    contact_stiffness: float = 0.0
    friction: float = 0.5
    contact_damping: float = 0.0
    restitution: float | None = None
    restitution_threshold: float = 0.2
    eps_v: float = 1e-3
    friction_iterations: int = 1
    kinematic_drive_stiffness: float = 1e4

    @classmethod
    def field_names(cls) -> list[str]:
        return [f.name for f in fields(cls)]

    def validate(self) -> None:
        """Raise TypeError for a setting of the wrong type, ValueError for one out of range.

        Flags must be ``bool`` (``contact='False'`` is refused, not read as True), numbers
        real numbers and counts integers (NumPy scalars such as ``np.float32(0.01)`` are
        fine; ``True`` is not a time step).
        """
        self._check_types()
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise ValueError(f"dt must be a positive finite number, got {self.dt!r}")
        g = np.asarray(self.gravity, dtype=np.float64)
        if g.shape != (3,) or not np.isfinite(g).all():
            raise ValueError(f"gravity must be 3 finite numbers, got {self.gravity!r}")
        if self.integrator not in _INTEGRATORS:
            raise ValueError(
                f"integrator must be one of {list(_INTEGRATORS)}, got {self.integrator!r}"
            )
        if self.linear_solver not in _LINEAR_SOLVERS:
            raise ValueError(
                f"linear_solver must be one of {list(_LINEAR_SOLVERS)}, got {self.linear_solver!r}"
            )
        positive = (
            "newton_tol_translation",
            "newton_tol_affine",
            "pcg_tolerance",
            "d_hat",
            "eps_v",
            "kinematic_drive_stiffness",
        )
        for name in positive:
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be positive and finite, got {v!r}")
        for name in ("newton_max_iterations", "line_search_max_iterations", "pcg_max_iterations"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)!r}")
        if not 0 < self.ccd_safety <= 1:
            raise ValueError(f"ccd_safety must be in (0, 1], got {self.ccd_safety!r}")
        if not 0 <= self.armijo_c < 1:
            raise ValueError(f"armijo_c must be in [0, 1), got {self.armijo_c!r}")
        for name in ("contact_stiffness", "friction", "contact_damping"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be finite and >= 0, got {v!r}")
        e = self.restitution
        if e is not None and not (math.isfinite(e) and 0 <= e <= 1):
            raise ValueError(f"restitution must be in [0, 1] or None, got {e!r}")
        v = self.restitution_threshold
        if not (math.isfinite(v) and v >= 0):
            raise ValueError(f"restitution_threshold must be finite and >= 0, got {v!r}")
        for name in ("direct_max_dofs", "num_threads", "history_limit", "friction_iterations"):
            if int(getattr(self, name)) < 0:
                raise ValueError(f"{name} must be >= 0, got {getattr(self, name)!r}")

    def _check_types(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            kind = _KINDS[f.name]
            if kind is bool:
                ok = isinstance(v, (bool, np.bool_))
            elif kind is str:
                ok = isinstance(v, str)
            elif kind is int:
                ok = isinstance(v, numbers.Integral) and not isinstance(v, (bool, np.bool_))
            elif kind is float or (kind == (float, type(None)) and v is not None):
                ok = isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))
            elif kind == (float, type(None)):
                ok = True  # None
            else:  # a vector of real numbers (its length is checked with the values)
                ok = isinstance(v, (tuple, list, np.ndarray)) and all(
                    isinstance(x, numbers.Real) and not isinstance(x, (bool, np.bool_))
                    for x in np.asarray(v, dtype=object).reshape(-1)
                )
            if not ok:
                raise TypeError(
                    f"setting {f.name} must be {_KIND_NAMES[kind]}, got {v!r} ({type(v).__name__})"
                )

    def to_core(self) -> _core.SolverSettings:
        """The C++ solver settings (validated)."""
        self.validate()
        s = _core.SolverSettings()
        s.integrator = _INTEGRATORS[self.integrator]
        s.tol_translation = float(self.newton_tol_translation)
        s.tol_affine = float(self.newton_tol_affine)
        s.max_newton_iterations = int(self.newton_max_iterations)
        s.friction_iterations = int(self.friction_iterations)
        s.max_line_search_iterations = int(self.line_search_max_iterations)
        s.armijo_c = float(self.armijo_c)
        s.ccd_safety = float(self.ccd_safety)
        s.linear_solver = _LINEAR_SOLVERS[self.linear_solver]
        s.direct_max_dofs = int(self.direct_max_dofs)
        s.pcg_tolerance = float(self.pcg_tolerance)
        s.pcg_max_iterations = int(self.pcg_max_iterations)
        s.kinematic_drive_stiffness = float(self.kinematic_drive_stiffness)
        s.project_psd = bool(self.project_psd)
        s.energies = bool(self.energies)
        s.num_threads = int(self.num_threads)
        return s
