"""Turns trajectories and mass properties into named checks with measured values and limits."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from abdsim.validation.restitution import restitution_table
from abdsim.validation.tolerances import Tolerances
from abdsim.validation.trajectory import Trajectory, rotation_angle


@dataclass
class Check:
    """One measured quantity against its limit. ``kind`` is ``"max"`` or ``"min"``."""

    name: str
    body: str
    value: float
    limit: float
    kind: str = "max"
    detail: str = ""

    @property
    def passed(self) -> bool:
        if not np.isfinite(self.value):
            return False
        return self.value <= self.limit if self.kind == "max" else self.value > self.limit

    def as_dict(self) -> dict:
        d = asdict(self)
        d["passed"] = self.passed
        return d


def relative_error(a: np.ndarray, b: np.ndarray) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b)) / max(float(np.max(np.abs(b))), 1e-300))


def inertia_checks(
    names: list[str], abd: list[tuple], ref: list[tuple], tol: Tolerances, reference: str
) -> tuple[list[Check], list[dict]]:
    """Mass, centre and inertia of each body against a reference (mass, centre, inertia)."""
    checks, rows = [], []
    for name, (ma, ca, ia), (mr, cr, ir) in zip(names, abd, ref, strict=True):
        scale = max(np.linalg.norm(cr), 1e-3)  # centre error relative to the body's size
        e_mass = relative_error(ma, mr)
        e_center = float(np.linalg.norm(np.asarray(ca) - cr) / scale)
        e_inertia = relative_error(ia, ir)
        worst = max(e_mass, e_center, e_inertia)
        rows.append(
            {
                "body": name,
                "reference": reference,
                "mass": float(ma),
                "mass_ref": float(mr),
                "mass_rel_err": e_mass,
                "center_rel_err": e_center,
                "inertia_rel_err": e_inertia,
            }
        )
        checks.append(
            Check(
                f"inertia vs {reference}",
                name,
                worst,
                tol.inertia_rel,
                detail=f"mass {e_mass:.2e}, centre {e_center:.2e}, inertia {e_inertia:.2e}",
            )
        )
    return checks, rows


def _window(traj: Trajectory, t_end: float) -> np.ndarray:
    return traj.time <= t_end + 1e-12


def free_flight_checks(
    abd: Trajectory, mj: Trajectory, pin: Trajectory | None, t_free: float, tol: Tolerances
) -> tuple[list[Check], dict]:
    """abdsim against MuJoCo (and Pinocchio) up to ``t_free``, per body."""
    wa, wm = _window(abd, t_free), _window(mj, t_free)
    n = min(wa.sum(), wm.sum())
    checks: list[Check] = []
    per_body: dict[str, dict] = {}
    pos = np.linalg.norm(abd.com[wa][:n] - mj.com[wm][:n], axis=-1).max(axis=0)
    rot = rotation_angle(abd.rotation[wa][:n], mj.rotation[wm][:n]).max(axis=0)
    if pin is not None:
        wp = _window(pin, t_free)
        m = min(n, wp.sum())
        pos_pin = np.linalg.norm(abd.com[wa][:m] - pin.com[wp][:m], axis=-1).max(axis=0)
        mj_pin = np.linalg.norm(mj.com[wm][:m] - pin.com[wp][:m], axis=-1).max(axis=0)
    L = abd.angular_momentum[wa]
    L0 = np.linalg.norm(L[0], axis=-1)
    drift_L = np.linalg.norm(L - L[0], axis=-1).max(axis=0) / np.maximum(L0, 1e-12)
    for i, name in enumerate(abd.names):
        checks.append(
            Check(
                "free-flight position vs MuJoCo [m]", name, float(pos[i]), tol.free_flight_position
            )
        )
        checks.append(
            Check(
                "free-flight orientation vs MuJoCo [rad]",
                name,
                float(rot[i]),
                tol.free_flight_orientation,
            )
        )
        body = {
            "position_error_mujoco": float(pos[i]),
            "orientation_error_mujoco": float(rot[i]),
            "angular_momentum_drift": float(drift_L[i]),
        }
        if L0[i] > 1e-9:
            checks.append(
                Check(
                    "free-flight angular momentum drift (rel)",
                    name,
                    float(drift_L[i]),
                    tol.angular_momentum_drift,
                )
            )
        if pin is not None:
            checks.append(
                Check(
                    "free-flight position vs Pinocchio [m]",
                    name,
                    float(pos_pin[i]),
                    tol.pinocchio_position,
                )
            )
            body["position_error_pinocchio"] = float(pos_pin[i])
            body["mujoco_vs_pinocchio"] = float(mj_pin[i])
        per_body[name] = body
    E = abd.energy[wa]
    drift_E = float(np.max(np.abs(E - E[0])) / max(abs(E[0]), 1e-12))
    checks.append(Check("free-flight energy drift (rel)", "all", drift_E, tol.energy_drift))
    return checks, {"t_free": float(t_free), "energy_drift": drift_E, "bodies": per_body}


def contact_checks(
    abd: Trajectory, mj: Trajectory, tol: Tolerances, masses: np.ndarray, d_hat: float
) -> tuple[list[Check], dict]:
    """What both models claim once bodies touch.

    * first contact: abdsim's first gap below d̂ against MuJoCo's first contact;
    * abdsim's smallest gap stays positive (intersection-free);
    * final heights, only for bodies at rest at the end in both simulators (bodies still
      bouncing are reported, not asserted);
    * restitution per impact of each body in both (abdsim.validation.restitution), reported:
      abdsim runs with the MJCF's solref damping ratio as its contact damping, so both
      model the same dissipation.
    """
    checks: list[Check] = []
    rest_abd, rest_mj = abd.com[-1, :, 2], mj.com[-1, :, 2]
    speed_abd = np.linalg.norm(abd.linear_momentum[-1], axis=-1) / masses
    speed_mj = np.linalg.norm(mj.linear_momentum[-1], axis=-1) / masses
    has_gap = np.isfinite(abd.contact_distance).any()
    min_gap = float(np.nanmin(abd.contact_distance)) if has_gap else float("nan")
    has_pen = np.isfinite(mj.contact_distance).any()
    max_pen = float(-np.nanmin(mj.contact_distance)) if has_pen else 0.0
    t_abd = abd.first_contact_time(d_hat)
    t_mj = mj.first_contact_time()
    summary = {
        "first_contact_abdsim": t_abd,
        "first_contact_mujoco": t_mj,
        "abdsim_min_contact_distance": min_gap,
        "mujoco_max_penetration": max_pen,
        "d_hat": d_hat,
        "bodies": {},
    }
    e_abd, e_mj = (
        restitution_table(
            tr.names, tr.linear_momentum[:, :, 2] / masses, float(np.diff(tr.time).mean())
        )
        for tr in (abd, mj)
    )
    if np.isfinite(t_mj):
        checks.append(
            Check(
                "first contact time vs MuJoCo [s]",
                "all",
                abs(t_abd - t_mj),
                tol.first_contact_time,
                detail=f"abdsim {t_abd:.3f} s, MuJoCo {t_mj:.3f} s",
            )
        )
    for i, name in enumerate(abd.names):
        at_rest = speed_abd[i] < tol.rest_speed and speed_mj[i] < tol.rest_speed
        dz = abs(float(rest_abd[i] - rest_mj[i]))
        if at_rest:
            checks.append(Check("final centre height vs MuJoCo [m]", name, dz, tol.rest_height))
        summary["bodies"][name] = {
            "rest_height_abdsim": float(rest_abd[i]),
            "rest_height_mujoco": float(rest_mj[i]),
            "final_speed_abdsim": float(speed_abd[i]),
            "final_speed_mujoco": float(speed_mj[i]),
            "at_rest_in_both": bool(at_rest),
            "restitution_abdsim": e_abd[name],
            "restitution_mujoco": e_mj[name],
        }
    if has_gap:
        checks.append(
            Check(
                "abdsim minimum contact distance [m]",
                "all",
                min_gap,
                tol.min_contact_distance,
                kind="min",
                detail="intersection-free: every gap stays positive",
            )
        )
    return checks, summary


def energy_gain_check(abd: Trajectory, tol: Tolerances) -> tuple[Check, dict]:
    """The whole run, contact included: abdsim's total energy (kinetic + gravity + the
    energy stored in the shape and barrier potentials) may fall (BDF1 and contact damping
    dissipate) but never rise between consecutive samples by more than ``tol.energy_gain``
    of its largest magnitude. A contact that adds energy (a barrier stiffened while
    compressed, a body started inside d̂ thrown up) fails it."""
    stored = np.asarray(abd.extra.get("stored_energy", np.zeros(len(abd.energy))), float)
    total = np.asarray(abd.energy, float) + stored
    scale = max(float(np.max(np.abs(total))), 1e-12)
    gains = np.diff(total) / scale
    worst = float(gains.max()) if len(gains) else 0.0
    at = float(abd.time[int(np.argmax(gains)) + 1]) if len(gains) else 0.0
    check = Check(
        "energy gain between samples (rel)",
        "all",
        max(worst, 0.0),
        tol.energy_gain,
        detail=f"largest at t = {at:.3f} s; total energy {total[0]:.4g} J -> {total[-1]:.4g} J",
    )
    return check, {
        "energy_gain": worst,
        "energy_gain_time": at,
        "energy_start": float(total[0]),
        "energy_end": float(total[-1]),
        "energy_max": float(total.max()),
    }
