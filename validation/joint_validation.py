"""``abdsim validate`` on a jointed MJCF scene (hinges, slides, balls; no free body): the
articulation in abdsim (exact joints, ``abdsim.bridges.build_articulated_scene``) against
MuJoCo RK4 on the same file from the same keyframe, joint by joint (positions and
velocities), and abdsim's joint violation at every step.

abdsim's joint coordinates are relative to the loaded configuration; MuJoCo's are absolute,
so a hinge or slide compares ``qpos0 + world.joint_positions()`` with ``data.qpos`` and a
ball the angle between ``q_load ⊗ q_abdsim`` and MuJoCo's quaternion. Velocities are in the
same convention on both sides (a ball's: the relative angular velocity in the child's frame),
compared as the norm of their difference.
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

from abdsim.sim.pose import quaternion_product_wxyz
from abdsim.validation.compare import Check
from abdsim.validation.report import write_metrics
from abdsim.validation.speed import speed_vs_mujoco
from abdsim.validation.tolerances import Tolerances


def has_joints_only(model) -> bool:
    """True for a model with hinge/slide/ball joints and no free joint."""
    import mujoco

    types = set(int(t) for t in model.jnt_type)
    return bool(types) and int(mujoco.mjtJoint.mjJNT_FREE) not in types


def floating_articulation(model) -> str | None:
    """The first joint that hangs below a free body (a floating robot's limb), or None."""
    import mujoco

    free = int(mujoco.mjtJoint.mjJNT_FREE)
    for j in range(model.njnt):
        if int(model.jnt_type[j]) == free:
            continue
        root = int(model.body_rootid[model.jnt_bodyid[j]])
        k = int(model.body_jntadr[root])
        if k >= 0 and int(model.jnt_type[k]) == free:
            return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint {j}"
    return None


def _coordinates(joints, adr, q_abd, q_load, qpos) -> tuple[np.ndarray, np.ndarray]:
    """(abdsim, MuJoCo) per-joint positions: hinge/slide values; a ball's angle from load."""
    ours, theirs, k = [], [], 0
    for j, a in zip(joints, adr, strict=True):
        if j.kind == "ball":
            q_ours = quaternion_product_wxyz(q_load[a : a + 4], q_abd[k : k + 4])
            dot = abs(float(np.dot(q_ours, qpos[a : a + 4])))
            ours.append(2.0 * np.arccos(min(dot, 1.0)))  # angle between the two rotations
            theirs.append(0.0)
        else:
            ours.append(q_load[a] + q_abd[k])
            theirs.append(qpos[a])
        k += j.nq
    return np.array(ours), np.array(theirs)


def _velocity_errors(joints, dof, v_abd, qvel) -> np.ndarray:
    """|abdsim − MuJoCo| of each joint's velocity (a ball's: the norm over its 3 dofs)."""
    out, k = [], 0
    for j, a in zip(joints, dof, strict=True):
        n = 3 if j.kind == "ball" else 1
        out.append(float(np.linalg.norm(v_abd[k : k + n] - qvel[a : a + n])))
        k += n
    return np.array(out)


def validate_joints(
    path: Path,
    duration: float,
    dt: float,
    out_dir: Path,
    tol: Tolerances,
    integrator: str,
    sample_dt: float,
):
    """Run and compare (see the module); returns a ``ValidationResult``."""
    import mujoco

    import abdsim
    from abdsim.bridges import build_articulated_scene, load_mjcf
    from abdsim.validation import plots
    from abdsim.validation.harness import ValidationResult, metrics_head

    t_start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = load_mjcf(path, kappa=1e10)
    # Links usually touch at their joints: the articulation is compared without contact.
    scene = build_articulated_scene(loaded, dt=dt, integrator=integrator, contact=False)
    world = abdsim.World(scene)
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.timestep = dt
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)  # as abdsim's side
    data = mujoco.MjData(model)
    if model.nkey > 0:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    joints = scene.joints
    adr = [int(model.jnt_qposadr[model.joint(j.name).id]) for j in joints]
    dof = [int(model.jnt_dofadr[model.joint(j.name).id]) for j in joints]
    q_load = data.qpos.copy()

    n_steps = int(round(duration / dt))
    every = max(1, int(round(sample_dt / dt)))
    times, ours, theirs = [0.0], [], []
    o, t = _coordinates(joints, adr, world.joint_positions(), q_load, data.qpos)
    ours.append(o)
    theirs.append(t)
    v_errors = [_velocity_errors(joints, dof, world.joint_velocities(), data.qvel)]
    violation = np.zeros(2)
    wall = {"abdsim": 0.0, "mujoco": 0.0}
    for k in range(1, n_steps + 1):
        t0 = time.perf_counter()
        d = world.step()
        wall["abdsim"] += time.perf_counter() - t0
        violation = np.maximum(violation, (d.joint_violation, d.joint_violation_angle))
        t0 = time.perf_counter()
        mujoco.mj_step(model, data)
        wall["mujoco"] += time.perf_counter() - t0
        if k % every == 0:
            times.append(k * dt)
            o, t = _coordinates(joints, adr, world.joint_positions(), q_load, data.qpos)
            ours.append(o)
            theirs.append(t)
            v_errors.append(_velocity_errors(joints, dof, world.joint_velocities(), data.qvel))
    time_s, ours, theirs = np.array(times), np.array(ours), np.array(theirs)
    errors = np.abs(ours - theirs).max(axis=0)
    v_error = np.max(v_errors, axis=0)

    checks = [
        Check("joint position vs MuJoCo RK4", j.name, float(e), tol.joint_position)
        for j, e in zip(joints, errors, strict=True)
    ]
    checks += [
        Check("joint velocity vs MuJoCo RK4", j.name, float(e), tol.joint_velocity)
        for j, e in zip(joints, v_error, strict=True)
    ]
    checks.append(Check("joint violation (m)", "all", float(violation[0]), tol.joint_violation))
    checks.append(Check("joint violation (rad)", "all", float(violation[1]), tol.joint_violation))
    passed = all(c.passed for c in checks)
    plot = plots.plot_joints(time_s, ours, theirs, [j.name for j in joints], out_dir / "joints.png")
    metrics = {
        **metrics_head(
            path,
            checks,
            tol,
            duration=duration,
            dt=dt,
            integrator=integrator,
            sample_dt=sample_dt,
            contact=False,
        ),
        "joints": {
            j.name: {"kind": j.kind, "max_error": float(e), "max_velocity_error": float(ev)}
            for j, e, ev in zip(joints, errors, v_error, strict=True)
        },
        "joint_violation": {"position": float(violation[0]), "angle": float(violation[1])},
        "free_flight": {},  # no free bodies (sweeps read this key)
        "timing": {
            "simulators": {
                name: {"steps": n_steps, "wall_time": w, "steps_per_s": n_steps / max(w, 1e-12)}
                for name, w in wall.items()
            },
            # one speed convention (abdsim.validation.speed): > 1 is faster
            "speed_vs_mujoco": speed_vs_mujoco(
                n_steps / max(wall["abdsim"], 1e-12), n_steps / max(wall["mujoco"], 1e-12)
            ),
            "total_wall_time": time.perf_counter() - t_start,
        },
        "files": {"joints": plot.name},
    }
    files = {"joints": plot, "metrics": write_metrics(out_dir / "metrics.json", metrics)}
    files["report"] = _write_report(out_dir / "report.md", metrics, checks)
    return ValidationResult(str(path), passed, checks, metrics, out_dir, files["report"], files)


def _write_report(path: Path, metrics: dict, checks: list[Check]) -> Path:
    s = metrics["settings"]
    failed = [c for c in checks if not c.passed]
    lines = [
        f"# abdsim validation — `{Path(metrics['scene']).name}` (joints)",
        "",
        f"**{'PASSED' if not failed else 'FAILED'}**: {len(checks) - len(failed)} of "
        f"{len(checks)} checks within tolerance. abdsim ({s['integrator'].upper()}, exact "
        f"joints, h = {s['dt']:g} s) against MuJoCo (RK4, h = {s['dt']:g} s) from the same "
        f"keyframe, {s['duration']:g} s simulated, without contact.",
        "",
        "| check | joint | value | limit | passed |",
        "|---|---|---|---|---|",
    ]
    lines += [
        f"| {c.name} | {c.body} | {c.value:.3g} | {c.kind} {c.limit:.3g} | "
        f"{'yes' if c.passed else '**no**'} |"
        for c in checks
    ]
    lines += ["", f"![joints]({metrics['files']['joints']})", ""]
    path.write_text("\n".join(lines))
    return path
