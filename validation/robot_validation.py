"""``abdsim validate robot.urdf``: the robot's own dynamics, joint by joint, against MuJoCo
(RK4) and Pinocchio (ABA + RK4 on the configuration manifold), from the same configuration
with zero control and without contact.

Compared at every sample: each joint's position and velocity (abdsim's are relative to the
loaded configuration: ``q_load + world.joint_positions()``), every link's joint-frame origin
against Pinocchio's ``oMi``, and the joints' violation measured from the source's joint
frames (``robot_setup.JointFrames``). MuJoCo and Pinocchio get abdsim's joint physics
(damping, armature, friction loss, limits; Pinocchio: damping only, the rest is noted).
A floating robot is dropped on the ground instead (``robot_drop``).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from abdsim.validation.compare import Check
from abdsim.validation.report import write_metrics
from abdsim.validation.speed import timing
from abdsim.validation.tolerances import Tolerances

#: κ of the compared links: stiff enough that their deformation is far below the tolerances
KAPPA = 1e10


def _absolute_limits(scene, q_load: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each joint's limits in absolute coordinates (±inf where it has none)."""
    lo, hi = np.full(len(q_load), -np.inf), np.full(len(q_load), np.inf)
    for k, j in enumerate(scene.joints):
        if j.limits is not None:
            lo[k], hi[k] = q_load[k] + j.limits[0], q_load[k] + j.limits[1]
    return lo, hi


def _per_joint(name: str, names: list[str], errors: np.ndarray, limit: float) -> list[Check]:
    return [Check(name, j, float(e), limit) for j, e in zip(names, errors, strict=True)]


def validate_robot(
    path: Path,
    duration: float,
    dt: float,
    out_dir: Path,
    tol: Tolerances,
    integrator: str = "bdf2",
    sample_dt: float = 0.01,
    q: np.ndarray | None = None,
    kappa: float = KAPPA,
    perturb_mass: dict[str, float] | None = None,
    perturb_anchor: dict[str, float] | None = None,
    perturb_axis: dict[str, float] | None = None,
    settings: dict | None = None,
):
    """Run and compare a fixed-base URDF robot (see the module); a ``ValidationResult``.

    Args:
        q: Pinocchio configuration to release the robot from (default: neutral, moved inside
            the joint limits).
        kappa: shape stiffness of the links.
        perturb_mass: {link: factor} scales a link's mass and inertia in abdsim only.
        perturb_anchor: {joint: metres} moves a joint's anchor across its axis in abdsim only.
        perturb_axis: {joint: radians} tilts a joint's axis in abdsim only.
        settings: other ``SceneSettings`` of abdsim's run (e.g. Newton tolerances).
    """
    import mujoco
    import pinocchio as pin

    import abdsim
    from abdsim.validation import plots
    from abdsim.validation.harness import ValidationResult, metrics_head
    from abdsim.validation.pinocchio_reference import rk4_step
    from abdsim.validation.robot_mujoco import joint_map, mujoco_robot
    from abdsim.validation.robot_setup import JointFrames, load_robot

    t_start = time.perf_counter()
    out_dir.mkdir(parents=True, exist_ok=True)
    result, scene, q0 = load_robot(
        path,
        q,
        floating=False,
        kappa=kappa,
        perturb_mass=perturb_mass,
        perturb_anchor=perturb_anchor,
        perturb_axis=perturb_axis,
        dt=dt,
        integrator=integrator,
        contact=False,  # links touch at their joints; the arm's own motion is compared
        **(settings or {}),
    )
    if not scene.joints:
        raise ValueError(f"{path}: the robot has no moving joint to compare")
    pin_model = result.model
    jm = joint_map(scene, pin_model)
    q_load = jm.pin_positions(q0)
    loads = dict(zip(jm.names, q_load, strict=True))
    mj, mj_path, mj_notes = mujoco_robot(path, out_dir, scene, loads)
    jm = joint_map(scene, pin_model, mj)
    notes = [
        f"{mj_path.name} (beside this report) is the URDF as MuJoCo compiled it: package:// "
        "mesh paths resolved, visuals dropped; its joints get abdsim's joint physics"
    ] + mj_notes
    damping = np.zeros(pin_model.nv)
    for j in scene.joints:
        damping[pin_model.idx_vs[pin_model.getJointId(j.name)]] = j.damping
        if j.armature or j.frictionloss or j.stiffness or j.limits is not None:
            notes.append(
                f"joint {j.name!r}: Pinocchio's reference has its damping only (armature, "
                "friction loss, spring and limits are MuJoCo's and abdsim's)"
            )

    world = abdsim.World(scene)
    mj.opt.timestep = dt
    mj.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    data = mujoco.MjData(mj)
    data.qpos[jm.mj_q] = q_load
    mujoco.mj_forward(mj, data)
    pin_data = pin_model.createData()
    pq, pv = q0.copy(), np.zeros(pin_model.nv)
    frames = JointFrames(result)
    links = [(j, i) for j, i in result.source_map.items() if j > 0]

    n_steps = int(round(duration / dt))
    every = max(1, int(round(sample_dt / dt)))
    keys = ("t", "q", "v", "q_mj", "v_mj", "q_pin", "v_pin", "links")
    rows: dict[str, list] = {k: [] for k in keys}
    violation = np.zeros(2)
    wall = {"abdsim": 0.0, "mujoco": 0.0, "pinocchio": 0.0}

    def sample(t: float) -> None:
        nonlocal violation
        rows["t"].append(t)
        rows["q"].append(q_load + world.joint_positions())
        rows["v"].append(world.joint_velocities())
        rows["q_mj"].append(data.qpos[jm.mj_q].copy())
        rows["v_mj"].append(data.qvel[jm.mj_v].copy())
        rows["q_pin"].append(jm.pin_positions(pq))
        rows["v_pin"].append(pv[jm.pin_v].copy())
        T = world.transforms()
        pin.forwardKinematics(pin_model, pin_data, pq)
        rows["links"].append(
            [np.linalg.norm(T[i][:3, 3] - pin_data.oMi[j].translation) for j, i in links]
        )
        violation = np.maximum(violation, frames.violation(T))

    sample(0.0)
    for k in range(1, n_steps + 1):
        t0 = time.perf_counter()
        world.step()
        t1 = time.perf_counter()
        mujoco.mj_step(mj, data)
        t2 = time.perf_counter()
        pq, pv = rk4_step(pin_model, pin_data, pq, pv, dt, damping)
        t3 = time.perf_counter()
        wall["abdsim"] += t1 - t0
        wall["mujoco"] += t2 - t1
        wall["pinocchio"] += t3 - t2
        if k % every == 0:
            sample(k * dt)
    r = {k: np.array(v) for k, v in rows.items()}
    # A continuous joint is (cos, sin) in Pinocchio: its angle, read in (-π, π], is unwrapped
    # over time like abdsim's and MuJoCo's.
    continuous = jm.pin_nq == 2
    r["q_pin"][:, continuous] = np.unwrap(r["q_pin"][:, continuous], axis=0)
    # Pinocchio has no joint limits: it is compared until its trajectory leaves them.
    lo, hi = _absolute_limits(scene, q_load)
    outside = np.flatnonzero(((r["q_pin"] < lo) | (r["q_pin"] > hi)).any(axis=1))
    n_pin = int(outside[0]) if len(outside) else len(r["t"])
    if n_pin < len(r["t"]):
        notes.append(
            f"Pinocchio (no joint limits) left the limits at t = {r['t'][n_pin]:.3g} s: "
            "compared with it up to then"
        )
    n_pin = max(n_pin, 1)
    err = {
        ("position", "MuJoCo RK4"): np.abs(r["q"] - r["q_mj"]).max(axis=0),
        ("position", "Pinocchio"): np.abs(r["q"] - r["q_pin"])[:n_pin].max(axis=0),
        ("velocity", "MuJoCo RK4"): np.abs(r["v"] - r["v_mj"]).max(axis=0),
        ("velocity", "Pinocchio"): np.abs(r["v"] - r["v_pin"])[:n_pin].max(axis=0),
    }
    link_error = r["links"][:n_pin].max(axis=0)
    checks: list[Check] = []
    for (what, ref), e in err.items():
        limit = tol.joint_position if what == "position" else tol.joint_velocity
        checks += _per_joint(f"joint {what} vs {ref}", jm.names, e, limit)
    names = [result.bodies[i].name for _, i in links]
    checks += [
        Check("link position vs Pinocchio", n, float(e), tol.link_position)
        for n, e in zip(names, link_error, strict=True)
    ]
    checks.append(Check("joint violation (m)", "all", float(violation[0]), tol.joint_violation))
    checks.append(Check("joint violation (rad)", "all", float(violation[1]), tol.joint_violation))

    files = {
        "joints": plots.plot_robot_joints(
            r["t"],
            {"abdsim": r["q"], "MuJoCo RK4": r["q_mj"], "Pinocchio": r["q_pin"]},
            jm.names,
            "position [rad or m]",
            out_dir / "joints.png",
        ).name,
        "joint_velocities": plots.plot_robot_joints(
            r["t"],
            {"abdsim": r["v"], "MuJoCo RK4": r["v_mj"], "Pinocchio": r["v_pin"]},
            jm.names,
            "velocity [rad/s or m/s]",
            out_dir / "joint_velocities.png",
        ).name,
    }
    metrics = {
        **metrics_head(
            path,
            checks,
            tol,
            mode="robot",
            duration=duration,
            dt=dt,
            integrator=integrator,
            sample_dt=sample_dt,
            kappa=kappa,
            contact=False,
            q0=q0.tolist(),
            perturb_mass=perturb_mass or {},
            perturb_anchor=perturb_anchor or {},
            perturb_axis=perturb_axis or {},
            scene_settings=settings or {},
        ),
        "joints": {
            n: {
                "max_position_error_mujoco": float(err[("position", "MuJoCo RK4")][k]),
                "max_position_error_pinocchio": float(err[("position", "Pinocchio")][k]),
                "max_velocity_error_mujoco": float(err[("velocity", "MuJoCo RK4")][k]),
                "max_velocity_error_pinocchio": float(err[("velocity", "Pinocchio")][k]),
                "travel": float(np.abs(r["q"][:, k] - q_load[k]).max()),
            }
            for k, n in enumerate(jm.names)
        },
        "links": {n: float(e) for n, e in zip(names, link_error, strict=True)},
        "joint_violation": {"position": float(violation[0]), "angle": float(violation[1])},
        "free_flight": {},  # no free bodies (sweeps read this key)
        "timing": timing(wall, n_steps, time.perf_counter() - t_start),
        "files": files,
        "notes": notes + list(result.notes),
    }
    out = {k: out_dir / v for k, v in files.items()}
    out["metrics"] = write_metrics(out_dir / "metrics.json", metrics)
    out["report"] = write_robot_report(out_dir / "report.md", metrics, checks)
    passed = all(c.passed for c in checks)
    return ValidationResult(str(path), passed, checks, metrics, out_dir, out["report"], out)


def write_robot_report(path: Path, metrics: dict, checks: list[Check]) -> Path:
    """report.md of a robot run: the verdict, every check, the plots and the notes."""
    s = metrics["settings"]
    failed = [c for c in checks if not c.passed]
    if s["mode"] == "robot":
        what = (
            f"abdsim ({s['integrator'].upper()}, exact joints, κ = {s['kappa']:g} Pa) against "
            "MuJoCo (RK4) and Pinocchio (ABA + RK4) from the same configuration with zero "
            "control, without contact"
        )
    else:
        held = (
            f"position actuators (kp = {s['kp']:.3g}, kv = {s['kv']:.3g})"
            if s.get("kp") is not None
            else "the file's actuators"
        )
        what = (
            f"the floating robot dropped {s['drop_height'] * 100:g} cm onto the ground under "
            f"{held} holding its stance, "
            f"abdsim ({s['integrator'].upper()}, κ = {s['kappa']:g} Pa) against MuJoCo "
            f"({s['mujoco_integrator']})"
        )
    lines = [
        f"# abdsim validation — `{Path(metrics['scene']).name}` ({s['mode']})",
        "",
        f"**{'PASSED' if not failed else 'FAILED'}**: {len(checks) - len(failed)} of "
        f"{len(checks)} checks within tolerance: {what}; h = {s['dt']:g} s, "
        f"{s['duration']:g} s simulated.",
        "",
        "| check | joint / link | value | limit | passed |",
        "|---|---|---|---|---|",
    ]
    lines += [
        f"| {c.name} | {c.body} | {c.value:.3g} | {c.kind} {c.limit:.3g} | "
        f"{'yes' if c.passed else '**no**'} |"
        for c in checks
    ]
    lines.append("")
    lines += [f"![{k}]({v})" for k, v in metrics["files"].items()]
    notes = metrics.get("notes", [])
    if notes:
        lines += ["", "Notes:", ""] + [f"- {n}" for n in notes]
    path.write_text("\n".join(lines) + "\n")
    return path
