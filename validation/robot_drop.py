"""``abdsim validate robot.urdf --floating``: a floating robot (free-flyer root) dropped onto
the ground with position actuators on every 1-dof joint holding its stance, against MuJoCo on
the same URDF (free joint, floor, the same actuators and gains, ``robot_mujoco``). An MJCF
robot whose root has a free joint is dropped the same way with its file's own model on both
sides (``robot_drop_mjcf``).

The robot starts at rest in its stance (the SRDF's ``standing`` state when the robot's
``srdf/`` folder has one, else Pinocchio's neutral inside the limits), lifted so that its
lowest point is ``drop_height`` above the ground. Both simulate robot–ground contacts only
(abdsim's links may collide with each other too: ``self_contact``). Compared: the base
height over time and after ``duration``, the final stance joint by joint; checked: abdsim's
gap at every step (its contact distance, and its lowest vertex above the ground), and
independently (coal, ``robot_gap``) at a few instants, and the joints' violation.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from abdsim.validation.compare import Check
from abdsim.validation.report import write_metrics
from abdsim.validation.speed import timing
from abdsim.validation.tolerances import Tolerances

#: κ of a dropped robot's links (the loaders' default)
KAPPA = 1e8
#: sliding friction of feet and ground in both simulators (MuJoCo's default)
FRICTION = 1.0


def standing_configuration(urdf: Path, model) -> tuple[np.ndarray, str]:
    """(configuration, where it came from): the SRDF ``standing`` state of the robot's
    ``srdf/`` folder (example-robot-data's layout), else the neutral one inside the limits."""
    import pinocchio as pin

    from abdsim.validation.robot_setup import default_configuration

    for folder in (urdf.parent.parent / "srdf", urdf.parent / "srdf"):
        for srdf in sorted(folder.glob("*.srdf")) if folder.is_dir() else []:
            try:
                pin.loadReferenceConfigurations(model, str(srdf), False)
            except (RuntimeError, ValueError):
                continue
            if "standing" in model.referenceConfigurations:
                return model.referenceConfigurations["standing"].copy(), f"{srdf.name} standing"
    return default_configuration(model), "neutral inside the joint limits"


def lowest_point(result) -> float:
    """Height of the lowest vertex of a loaded robot (its moving bodies)."""
    low = np.inf
    for body in result.bodies:
        if body.kind == "fixed":  # an MJCF file's scenery
            continue
        T = body.transform
        z = np.asarray(body.geometry.positions) @ T[2, :3] + T[2, 3]
        low = min(low, float(z.min()))
    return low


def default_gains(result) -> tuple[float, float]:
    """(kp, kv) scaled by the robot's weight: 2 N·m/rad per kg, kv = kp / 50 (solo12: 5,
    0.1)."""
    import abdsim

    mass = sum(abdsim.to_rigid_body(b.geometry).mass for b in result.bodies)
    kp = 2.0 * mass
    return kp, kp / 50.0


@dataclass
class DropSetup:
    """A floating robot ready to drop in both simulators."""

    result: object
    scene: object
    world: object
    mj_model: object
    mj_data: object
    base: int  #: abdsim body index of the floating base
    mj_base: int  #: MuJoCo body id of the base
    q_load: np.ndarray  #: joint coordinates at load (abdsim's zero), scene joint order
    names: list[str]
    mj_q: np.ndarray
    kp: float | None  #: None: the MJCF file's own actuators
    kv: float | None
    stance: str
    mj_path: Path
    notes: list[str]  #: what the MuJoCo twin changed
    world_q: np.ndarray | None = None  #: ``names``' entries of world.joint_positions()

    def joint_positions(self) -> np.ndarray:
        """abdsim's compared joint coordinates, absolute (MuJoCo's convention)."""
        q = self.world.joint_positions()
        return self.q_load + (q[self.world_q] if self.world_q is not None else q[: len(self.names)])


def drop_setup(
    path: Path,
    out_dir: Path,
    dt: float,
    integrator: str = "bdf2",
    q: np.ndarray | None = None,
    drop_height: float = 0.05,
    kp: float | None = None,
    kv: float | None = None,
    kappa: float = KAPPA,
    mujoco_integrator: str = "RK4",
    perturb_mass: dict[str, float] | None = None,
    perturb_anchor: dict[str, float] | None = None,
    perturb_axis: dict[str, float] | None = None,
    settings: dict | None = None,
    self_contact: bool = False,
    friction: float = FRICTION,
) -> DropSetup:
    """Both simulators' robot at rest, ``drop_height`` above the ground, actuated; the
    ``perturb_*`` wrong models (abdsim only) are ``robot_setup.articulate``'s; ``settings``
    are abdsim scene settings (``contact=False``: a wrong model whose gap checks fail).

    Both simulate the same contacts, robot–ground only; ``self_contact`` lets abdsim's links
    collide too (those the loader does not exclude: not adjacent, not touching at load),
    which a stance never needs and which costs most of a step (the broad phase between a
    trunk's and its legs' dense meshes). ``friction``: μ of every foot–ground pair in both
    (the final stance depends on where the feet stick on landing: go2 stands 12.7 mm higher
    than in MuJoCo at μ = 1, within 1.3 mm at μ = 0.02)."""
    import mujoco
    import pinocchio as pin

    import abdsim
    from abdsim.validation.robot_mujoco import joint_map, mujoco_robot
    from abdsim.validation.robot_setup import articulate, lift, load_result

    out_dir.mkdir(parents=True, exist_ok=True)
    stance = "given"
    if q is None:
        model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        q, stance = standing_configuration(path, model)
    result, q = load_result(path, q, floating=True, kappa=kappa)
    result = lift(result, drop_height - lowest_point(result))
    q = result.q
    if not self_contact:
        n = len(result.bodies)
        result.contact_rules.excluded |= {(i, j) for i in range(n) for j in range(i + 1, n)}
    if kp is None or kv is None:
        kp0, kv0 = default_gains(result)  # the robot's own weight, before any perturbation
        kp, kv = kp if kp is not None else kp0, kv if kv is not None else kv0
    settings = {"friction": friction, **(settings or {})}
    scene = articulate(
        result,
        perturb_mass,
        perturb_anchor,
        perturb_axis,
        dt=dt,
        integrator=integrator,
        **settings,
    )
    scene.add_ground(0.0)
    joints = [j for j in scene.joints if j.kind in ("revolute", "prismatic")]
    for j in joints:
        scene.add_actuator(j, "position", kp=kp, kv=kv)  # ctrl 0: hold the loaded stance
    free = [j for j in result.joints if j.type == "free"]
    if not free:
        raise ValueError(f"{path}: no floating base (load with floating_base=True)")
    base = free[0].child
    world = abdsim.World(scene)

    jm = joint_map(_JointsOnly(joints), result.model)
    q_load = jm.pin_positions(q)
    loads = dict(zip(jm.names, q_load, strict=True))
    mj, mj_path, mj_notes = mujoco_robot(
        path,
        out_dir,
        _JointsOnly(joints),
        loads,
        floating=True,
        friction=friction,
        actuators=[(j.name, kp, kv) for j in joints],
    )
    jm = joint_map(_JointsOnly(joints), result.model, mj)
    mj.opt.timestep = dt
    mj.opt.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{mujoco_integrator.upper()}")
    data = mujoco.MjData(mj)
    root = int(mj.body_rootid[mj.jnt_bodyid[_free_joint(mj)]])
    adr = int(mj.jnt_qposadr[_free_joint(mj)])
    data.qpos[adr : adr + 3] = q[:3]
    data.qpos[adr + 3 : adr + 7] = [q[6], q[3], q[4], q[5]]  # Pinocchio xyzw -> MuJoCo wxyz
    data.qpos[jm.mj_q] = q_load
    data.ctrl[:] = q_load
    mujoco.mj_forward(mj, data)
    return DropSetup(
        result, scene, world, mj, data, base, root, q_load, jm.names, jm.mj_q, kp, kv,
        stance, mj_path, [_twin_note(mj_path)] + mj_notes,
    )  # fmt: skip


def _twin_note(mj_path: Path) -> str:
    return (
        f"{mj_path.name} (beside this report) is the URDF as MuJoCo compiled it, with a free "
        "joint on its root, a floor and position actuators; only robot–floor contacts in "
        "MuJoCo (and in abdsim unless self_contact)"
    )


class _JointsOnly:
    """A scene-like view holding only the given joints (the 1-dof ones)."""

    def __init__(self, joints) -> None:
        self.joints = joints


def _free_joint(mj) -> int:
    import mujoco

    free = np.flatnonzero(mj.jnt_type == mujoco.mjtJoint.mjJNT_FREE)
    return int(free[0])


def mujoco_penetration(mj, data) -> float:
    """Largest penetration depth among MuJoCo's current contacts (0 when none)."""
    n = data.ncon
    return float(max(0.0, -min((c.dist for c in data.contact[:n]), default=0.0)))


def validate_drop(
    path: Path,
    duration: float,
    dt: float,
    out_dir: Path,
    tol: Tolerances,
    integrator: str = "bdf2",
    sample_dt: float = 0.01,
    gap_checks: int = 4,
    **options,
):
    """Drop and compare (see the module); a ``ValidationResult``. ``options`` go to
    ``drop_setup`` (q, drop_height, kp, kv, kappa, perturb_mass / _anchor / _axis,
    settings), or for an MJCF robot with a free root to ``robot_drop_mjcf.mjcf_drop_setup``
    (the file's own actuators, stance and floor)."""
    import mujoco

    from abdsim.validation import plots
    from abdsim.validation.harness import ValidationResult, metrics_head
    from abdsim.validation.robot_drop_mjcf import mjcf_drop_setup
    from abdsim.validation.robot_gap import coal_gaps
    from abdsim.validation.robot_setup import JointFrames
    from abdsim.validation.robot_validation import write_robot_report

    t_start = time.perf_counter()
    mjcf = path.suffix.lower() in (".xml", ".mjcf")
    s = (mjcf_drop_setup if mjcf else drop_setup)(path, out_dir, dt, integrator, **options)
    world, mj, data = s.world, s.mj_model, s.mj_data
    frames = JointFrames(s.result)
    n_steps = int(round(duration / dt))
    every = max(1, int(round(sample_dt / dt)))
    coal_at = {int(round(n_steps * (k + 1) / gap_checks)) for k in range(gap_checks)}
    rows: dict[str, list] = {k: [] for k in ("t", "z", "z_mj", "q", "q_mj")}
    gap, penetration = np.inf, 0.0
    coal_ground, coal_pairs, coal_hits = np.inf, np.inf, 0
    violation = np.zeros(2)
    wall = {"abdsim": 0.0, "mujoco": 0.0}

    def sample(t: float) -> None:
        rows["t"].append(t)
        rows["z"].append(world.transforms()[s.base][2, 3])
        rows["z_mj"].append(data.xpos[s.mj_base][2])
        rows["q"].append(s.joint_positions())
        rows["q_mj"].append(data.qpos[s.mj_q].copy())

    table = s.scene.contact_table
    grounded = [h for h in s.scene.handles if table.get(h.contact_elements[0], "ground")[0]]
    sample(0.0)
    for k in range(1, n_steps + 1):
        t0 = time.perf_counter()
        d = world.step()
        t1 = time.perf_counter()
        mujoco.mj_step(mj, data)
        t2 = time.perf_counter()
        wall["abdsim"] += t1 - t0
        wall["mujoco"] += t2 - t1
        # abdsim's own smallest contact distance (inf while nothing is near) and, so that a
        # body sunk into the ground shows even without contact, its lowest vertex's height.
        lowest = min(float(world.vertices(h)[..., 2].min()) for h in grounded)
        gap = min(gap, float(d.min_contact_distance), lowest)
        penetration = max(penetration, mujoco_penetration(mj, data))
        violation = np.maximum(violation, frames.violation(world.transforms()))
        if k in coal_at:
            g, p, h = coal_gaps(world)
            coal_ground, coal_pairs, coal_hits = (
                min(coal_ground, g),
                min(coal_pairs, p),
                coal_hits + h,
            )
        if k % every == 0:
            sample(k * dt)
    r = {k: np.array(v) for k, v in rows.items()}
    height_error = abs(float(r["z"][-1] - r["z_mj"][-1]))
    stance_error = np.abs(r["q"][-1] - r["q_mj"][-1])
    checks = [Check("base height vs MuJoCo at the end", "base", height_error, tol.base_height)]
    checks += [
        Check("final stance vs MuJoCo", n, float(e), tol.stance)
        for n, e in zip(s.names, stance_error, strict=True)
    ]
    checks.append(Check("abdsim gap, every step", "all", gap, tol.min_contact_distance, "min"))
    checks.append(Check("ground gap (coal)", "all", coal_ground, tol.min_contact_distance, "min"))
    checks.append(Check("intersections (coal)", "all", float(coal_hits), 0.0))
    checks.append(Check("joint violation (m)", "all", float(violation[0]), tol.joint_violation))
    checks.append(Check("joint violation (rad)", "all", float(violation[1]), tol.joint_violation))

    files = {
        "base_height": plots.plot_base_height(
            r["t"], {"abdsim": r["z"], "MuJoCo": r["z_mj"]}, out_dir / "base_height.png"
        ).name,
        "joints": plots.plot_robot_joints(
            r["t"],
            {"abdsim": r["q"], "MuJoCo": r["q_mj"]},
            s.names,
            "position [rad or m]",
            out_dir / "joints.png",
        ).name,
    }
    metrics = {
        **metrics_head(
            path,
            checks,
            tol,
            mode="robot-drop",
            duration=duration,
            dt=dt,
            integrator=integrator,
            mujoco_integrator=str(options.get("mujoco_integrator", "RK4")).upper(),
            sample_dt=sample_dt,
            kappa=float(options.get("kappa", KAPPA)),
            kp=s.kp,
            kv=s.kv,
            drop_height=float(options.get("drop_height", 0.05)),
            friction=None if mjcf else float(options.get("friction", FRICTION)),
            stance=s.stance,
            self_contact=bool(options.get("self_contact", False)),
            **{k: options.get(k) or {} for k in ("perturb_mass", "perturb_anchor", "perturb_axis")},
        ),
        "base_height": {
            "abdsim_end": float(r["z"][-1]),
            "mujoco_end": float(r["z_mj"][-1]),
            "max_difference": float(np.abs(r["z"] - r["z_mj"]).max()),
        },
        "stance": {n: float(e) for n, e in zip(s.names, stance_error, strict=True)},
        "gaps": {
            "abdsim_min_gap": gap,
            "coal_min_ground_gap": coal_ground,
            "coal_min_pair_gap": coal_pairs,
            "coal_intersecting_pairs": coal_hits,
            "mujoco_max_penetration": penetration,
        },
        "joint_violation": {"position": float(violation[0]), "angle": float(violation[1])},
        "free_flight": {},
        "timing": timing(wall, n_steps, time.perf_counter() - t_start),
        "files": files,
        "notes": [f"stance: {s.stance}; MuJoCo's largest penetration {penetration:.3g} m"]
        + s.notes
        + list(s.result.notes),
    }
    out = {k: out_dir / v for k, v in files.items()}
    out["metrics"] = write_metrics(out_dir / "metrics.json", metrics)
    out["report"] = write_robot_report(out_dir / "report.md", metrics, checks)
    passed = all(c.passed for c in checks)
    return ValidationResult(str(path), passed, checks, metrics, out_dir, out["report"], out)
