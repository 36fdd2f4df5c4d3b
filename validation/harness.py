"""``abdsim validate``: one scene in abdsim, MuJoCo and Pinocchio, compared and reported."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from abdsim.validation import plots
from abdsim.validation.compare import (
    Check,
    contact_checks,
    energy_gain_check,
    free_flight_checks,
    inertia_checks,
)
from abdsim.validation.report import write_metrics, write_report
from abdsim.validation.scenes import default_scene, scene_kind
from abdsim.validation.speed import speed_vs_mujoco
from abdsim.validation.tolerances import Tolerances
from abdsim.validation.trajectory import Trajectory


@dataclass
class ValidationResult:
    """What ``validate`` found. ``passed`` is False if any check exceeded its tolerance."""

    scene: str
    passed: bool
    checks: list[Check]
    metrics: dict
    out_dir: Path
    report: Path
    files: dict[str, Path] = field(default_factory=dict)
    trajectories: dict[str, Trajectory] = field(default_factory=dict)

    @property
    def failed(self) -> list[Check]:
        return [c for c in self.checks if not c.passed]


def metrics_head(path: Path, checks: list[Check], tol: Tolerances, **settings) -> dict:
    """The first entries of every metrics.json: scene, verdict, settings (MuJoCo runs RK4),
    tolerances and checks."""
    return {
        "scene": str(path),
        "passed": all(c.passed for c in checks),
        "settings": {"mujoco_integrator": "RK4", **settings},
        "tolerances": tol.as_dict(),
        "checks": [c.as_dict() for c in checks],
    }


def validate(
    scene: str | Path | None = None,
    duration: float = 2.0,
    dt: float = 1e-3,
    out: str | Path = "abdsim_out/validation",
    tolerances: str | Path | Tolerances | None = None,
    integrator: str = "bdf2",
    sample_dt: float = 0.01,
    progress: bool = True,
    mcap: bool = True,
    perturb_inertia: dict[str, float] | None = None,
    floating: bool = False,
    robot: dict | None = None,
) -> ValidationResult:
    """Run ``scene`` (MJCF or URDF; default: the bundled tossed-bodies scene) and compare.

    Args:
        scene: path to an MJCF (.xml/.mjcf) or URDF (.urdf) file.
        duration: simulated time [s].
        dt: time step of every simulator [s].
        out: output folder for report.md, metrics.json, plots and run.mcap.
        tolerances: a Tolerances, or a JSON/TOML file of overrides.
        integrator: abdsim's integrator, ``"bdf2"`` (default) or ``"bdf1"``.
        sample_dt: interval between recorded samples [s].
        progress: show progress bars.
        mcap: also write run.mcap with both simulators' poses.
        perturb_inertia: {body name: factor} scales those bodies' inertia in abdsim only —
            a deliberately wrong model, to see the harness catch it.
        floating: a URDF robot gets a floating base and is dropped on the ground
            (``robot_drop``) instead of released from a fixed base (``robot_validation``).
            An MJCF robot whose root has a free joint is always dropped (``robot_drop_mjcf``:
            the file's own actuators, stance and floor).
        robot: options of a URDF robot's run: ``q`` (Pinocchio configuration), ``kappa``,
            wrong models ``perturb_mass`` {link: factor}, ``perturb_anchor`` {joint: m},
            ``perturb_axis`` {joint: rad}, ``settings`` (abdsim scene settings); dropped
            robots also ``kp``, ``kv``, ``drop_height``, ``friction`` and ``self_contact``; a
            floating MJCF robot takes ``kappa``, ``drop_height``, the wrong models and
            ``settings``.

    Raises:
        ValueError: unknown file type, a model MuJoCo or Pinocchio rejects, a scene with
            nothing dynamic, bad tolerance files.
        FileNotFoundError: a missing scene or tolerance file.
    """
    from abdsim.validation.mujoco_reference import run_mujoco
    from abdsim.validation.pinocchio_reference import run_pinocchio_free_flight
    from abdsim.validation.scene_setup import build_abdsim, peer_inertias

    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be positive, got {duration}")
    if not (np.isfinite(dt) and dt > 0 and dt < duration):
        raise ValueError(f"dt must be positive and smaller than the duration, got {dt}")
    tol = (
        tolerances
        if isinstance(tolerances, Tolerances)
        else (Tolerances.from_file(tolerances) if tolerances is not None else Tolerances())
    ).at_step(dt, integrator)
    path = Path(scene) if scene is not None else default_scene()
    kind = scene_kind(path)
    out_dir = Path(out)
    out_dir.mkdir(parents=True, exist_ok=True)

    if kind == "urdf":
        return _validate_urdf_robot(
            path, duration, dt, out_dir, tol, integrator, sample_dt, floating, robot or {}
        )
    if floating:
        raise ValueError(f"{path}: --floating applies to URDF robots (an MJCF file has its own)")
    from abdsim.validation.joint_validation import (
        floating_articulation,
        has_joints_only,
        validate_joints,
    )
    from abdsim.validation.mujoco_reference import load_model

    model = load_model(path)
    if has_joints_only(model):  # an articulation: joint trajectories
        return validate_joints(path, duration, dt, out_dir, tol, integrator, sample_dt)
    if floating_articulation(model) is not None:  # a floating robot: dropped (robot_drop)
        from abdsim.validation.robot_drop import validate_drop

        return validate_drop(
            path, duration, dt, out_dir, tol, integrator, sample_dt, **(robot or {})
        )

    t_start = time.perf_counter()
    setup = build_abdsim(
        path, kind, dt=dt, integrator=integrator, perturb_inertia=perturb_inertia or {}
    )
    end_to_end: dict[str, float] = {}  # wall time of each whole run, sampling and logging in
    t0 = time.perf_counter()
    mj = run_mujoco(setup.mujoco_path, duration, dt, sample_dt)
    end_to_end["mujoco"] = time.perf_counter() - t0
    if mj.names != setup.names:
        raise ValueError(f"body mismatch between abdsim {setup.names} and MuJoCo {mj.names}")
    t_contact = mj.first_contact_time()
    # Compare free flight up to shortly before MuJoCo's first contact (its contacts start at
    # penetration; abdsim's barrier acts within d̂ before touching).
    t_free = min(duration, t_contact - 0.02) if np.isfinite(t_contact) else duration
    t0 = time.perf_counter()
    pin = run_pinocchio_free_flight(setup.mujoco_path, max(t_free, sample_dt), dt, sample_dt)
    end_to_end["pinocchio"] = time.perf_counter() - t0
    logger = setup.make_logger(out_dir / "run.mcap") if mcap else None
    try:
        t0 = time.perf_counter()
        abd = setup.run(duration, sample_dt, progress=progress, logger=logger)
        end_to_end["abdsim"] = time.perf_counter() - t0
        if logger is not None:
            setup.log_reference(logger, mj, "/mujoco")
    finally:
        if logger is not None:
            logger.close()

    checks: list[Check] = []
    abd_inertia = setup.rigid_bodies()
    inertia_rows = []
    for ref_name, ref in peer_inertias(setup).items():
        c, rows = inertia_checks(setup.names, abd_inertia, ref, tol, ref_name)
        checks += c
        inertia_rows += rows
    ff: dict = {}
    if t_free >= sample_dt:  # a scene that starts in contact has no free-flight phase
        ff_checks, ff = free_flight_checks(abd, mj, pin, t_free, tol)
        checks += ff_checks
    e_check, energy = energy_gain_check(abd, tol)
    checks.append(e_check)
    contact = {}
    # Contact phases are compared only where abdsim simulates contact (a World that reports
    # contact distances); otherwise the report says the phase was not compared.
    has_contact = callable(getattr(setup.world, "min_contact_distance", None))
    if has_contact and np.isfinite(t_contact) and t_contact < duration:
        masses = np.array([m for m, _, _ in setup.rigid_bodies()])
        d_hat = float(getattr(setup.world.scene.settings, "d_hat", 0.0))
        c_checks, contact = contact_checks(abd, mj, tol, masses, d_hat)
        checks += c_checks

    plot_files = {"heights": plots.plot_heights(abd, mj, out_dir / "heights.png").name}
    if ff:
        plot_files["free_flight"] = plots.plot_free_flight_errors(
            abd, mj, pin, t_free, out_dir / "free_flight.png"
        ).name
    plot_files["conservation"] = plots.plot_conservation(
        [abd, mj, pin], max(t_free, 0.0), out_dir / "conservation.png"
    ).name
    if contact:
        plot_files["contact"] = plots.plot_contact(
            abd, mj, out_dir / "contact.png", d_hat=contact.get("d_hat")
        ).name
    geoms = [setup.loaded.bodies[i].geometry for i in setup.body_ids]
    plot_files["snapshots"] = plots.plot_snapshots(
        abd,
        mj,
        [(g.positions, g.triangles) for g in geoms],
        np.array([c for _, c, _ in setup.rigid_bodies()]),
        out_dir / "snapshots.png",
    ).name

    newton = abd.extra.get("newton_iterations")
    # Speeds follow abdsim.validation.speed: N× MuJoCo's speed, > 1 is faster; "stepping"
    # times step() alone, "end to end" the whole run (sampling, and abdsim's MCAP log).
    sims = {
        tr.simulator: {
            "steps": tr.steps,
            "wall_time": tr.wall_time,
            "steps_per_s": tr.steps / max(tr.wall_time, 1e-12),
            "end_to_end_wall_time": end_to_end[tr.simulator],
            "end_to_end_steps_per_s": tr.steps / max(end_to_end[tr.simulator], 1e-12),
        }
        for tr in (abd, mj, pin)
    }
    timing = {
        "simulators": sims,
        "speed_vs_mujoco": speed_vs_mujoco(
            sims["abdsim"]["steps_per_s"], sims["mujoco"]["steps_per_s"]
        ),
        "speed_vs_mujoco_end_to_end": speed_vs_mujoco(
            sims["abdsim"]["end_to_end_steps_per_s"], sims["mujoco"]["end_to_end_steps_per_s"]
        ),
        "mean_newton_iterations": float(np.mean(newton))
        if newton is not None and len(newton)
        else None,
        "total_wall_time": time.perf_counter() - t_start,
    }
    passed = all(c.passed for c in checks)
    metrics = {
        **metrics_head(
            path,
            checks,
            tol,
            duration=duration,
            dt=dt,
            integrator=integrator,
            sample_dt=sample_dt,
            perturb_inertia=perturb_inertia or {},
            **setup.settings(),
        ),
        "inertia": inertia_rows,
        "free_flight": ff,
        "energy": energy,
        "contact": contact,
        "timing": timing,
        "files": {k: v for k, v in plot_files.items()},
        "notes": []
        if has_contact
        else ["this abdsim build has no contact: the contact phase was not compared"],
    }
    files = {k: out_dir / v for k, v in plot_files.items()}
    files["metrics"] = write_metrics(out_dir / "metrics.json", metrics)
    files["report"] = write_report(out_dir / "report.md", metrics, checks, plot_files)
    if mcap:
        files["mcap"] = out_dir / "run.mcap"
    return ValidationResult(
        str(path),
        passed,
        checks,
        metrics,
        out_dir,
        files["report"],
        files,
        {"abdsim": abd, "mujoco": mj, "pinocchio": pin},
    )


def _validate_urdf_robot(
    path: Path,
    duration: float,
    dt: float,
    out_dir: Path,
    tol: Tolerances,
    integrator: str,
    sample_dt: float,
    floating: bool,
    options: dict,
) -> ValidationResult:
    """A URDF robot: its dynamics (fixed base: joint trajectories; floating: a drop) and the
    mass properties of every link against Pinocchio and MuJoCo; a robot without moving
    joints gets the mass properties only."""
    import pinocchio as pin

    from abdsim.validation.robot_drop import validate_drop
    from abdsim.validation.robot_validation import validate_robot, write_robot_report

    if floating:
        return validate_drop(path, duration, dt, out_dir, tol, integrator, sample_dt, **options)
    try:
        moving = pin.buildModelFromUrdf(str(path)).nv > 0
    except (RuntimeError, ValueError) as err:
        raise ValueError(f"Pinocchio could not load URDF {path}: {err}") from err
    if not moving:
        return _validate_urdf_inertias(path, out_dir, tol)
    res = validate_robot(path, duration, dt, out_dir, tol, integrator, sample_dt, **options)
    inertia = _validate_urdf_inertias(path, out_dir / "inertia", tol, options.get("perturb_mass"))
    res.checks[:0] = inertia.checks
    res.metrics["inertia"] = inertia.metrics["inertia"]
    res.metrics["checks"] = [c.as_dict() for c in res.checks]
    res.metrics["passed"] = res.passed = all(c.passed for c in res.checks)
    res.files["metrics"] = write_metrics(out_dir / "metrics.json", res.metrics)
    res.files["report"] = write_robot_report(res.report, res.metrics, res.checks)
    return res


def _validate_urdf_inertias(
    path: Path, out_dir: Path, tol: Tolerances, perturb_mass: dict[str, float] | None = None
) -> ValidationResult:
    """A URDF robot: mass properties against Pinocchio and MuJoCo (see urdf_check)."""
    from abdsim.validation.urdf_check import urdf_inertia_comparisons

    out_dir.mkdir(parents=True, exist_ok=True)
    comparisons, notes = urdf_inertia_comparisons(path, out_dir, perturb_mass)
    checks: list[Check] = []
    rows: list[dict] = []
    for reference, names, abd, ref in comparisons:
        c, r = inertia_checks(names, abd, ref, tol, reference)
        checks += c
        rows += r
    passed = all(c.passed for c in checks)
    metrics = {
        "scene": str(path),
        "passed": passed,
        "settings": {"mode": "urdf-inertia"},
        "tolerances": tol.as_dict(),
        "checks": [c.as_dict() for c in checks],
        "inertia": rows,
        "free_flight": {},
        "contact": {},
        "timing": {},
        "notes": notes,
    }
    files = {"metrics": write_metrics(out_dir / "metrics.json", metrics)}
    files["report"] = write_report(out_dir / "report.md", metrics, checks, {})
    return ValidationResult(str(path), passed, checks, metrics, out_dir, files["report"], files)
