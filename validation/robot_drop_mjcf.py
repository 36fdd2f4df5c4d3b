"""``abdsim validate robot.xml`` on an MJCF robot whose root body has a free joint: the drop
of ``robot_drop`` with the file's own model on both sides.

Both simulators load the same file, rewritten once (``mjcf_twin``, beside the report) so that
the robot's lowest point starts ``drop_height`` above the ground: only the free joint's height
changes (in the first keyframe, else the root body's position). Everything else is the
file's: its keyframe (or ``qpos0``) stance, joint physics, contact filter and friction, floor,
and actuators. The controls hold the stance: a position-like actuator (an affine bias with
``b1 < 0``) gets the control whose target is the joint's loaded position, ``u = −b1/g·L0``
(``L0``: the actuator length at load), clamped to its control range; every other one zero.
Both simulators get the same controls: the loader folds ``b1·L0`` into abdsim's actuator bias,
since abdsim's joint coordinates start at the loaded configuration.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from abdsim.validation.robot_drop import DropSetup, lowest_point

#: κ of the robot's bodies (the loaders' default)
KAPPA = 1e8


def free_root(model) -> tuple[int, int]:
    """(free joint id, its body id) of a floating MJCF robot.

    Raises:
        ValueError: no free joint, or several (one robot is dropped at a time).
    """
    import mujoco

    free = np.flatnonzero(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE)
    if len(free) != 1:
        raise ValueError(
            f"a dropped MJCF robot has exactly one free joint (its root); this model has "
            f"{len(free)}"
        )
    return int(free[0]), int(model.jnt_bodyid[free[0]])


def mjcf_twin(path: Path, out_dir: Path, dz: float) -> Path:
    """The MJCF ``path`` with its free root ``dz`` higher (first keyframe, else the root
    body), written to ``out_dir``; asset folders are made absolute so that it compiles
    there."""
    import mujoco

    spec = mujoco.MjSpec.from_file(str(path))
    model = spec.compile()
    joint, body = free_root(model)
    base = path.resolve().parent
    for attr in ("meshdir", "texturedir"):
        folder = getattr(spec, attr)
        setattr(spec, attr, str(base / folder) if folder else str(base))
    if model.nkey > 0:
        key = spec.keys[0]
        qpos = np.array(key.qpos) if len(key.qpos) else np.array(model.qpos0)
        qpos[int(model.jnt_qposadr[joint]) + 2] += dz
        key.qpos = qpos.tolist()
    else:
        root = spec.body(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body))
        root.pos = [root.pos[0], root.pos[1], root.pos[2] + dz]
    twin = out_dir / f"{path.stem}_drop.xml"
    twin.write_text(spec.to_xml())
    return twin


def _load(path: Path, kappa: float):
    from abdsim.bridges import load_mjcf

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the loader's notes are in result.notes
        return load_mjcf(path, kappa=kappa)


def hold_controls(mj, data, result) -> tuple[np.ndarray, np.ndarray]:
    """(MuJoCo ctrl, abdsim ctrl in ``result.actuator_ids`` order) holding the loaded
    stance (see the module); ``data`` is at the loaded state."""
    u = np.zeros(mj.nu)
    for a in range(mj.nu):
        g = float(mj.actuator_gainprm[a, 0])
        b1 = float(mj.actuator_biasprm[a, 1])
        if int(mj.actuator_biastype[a]) != 1 or g == 0.0 or b1 >= 0.0:  # 1: mjBIAS_AFFINE
            continue
        u[a] = -b1 / g * float(data.actuator_length[a])
        if int(mj.actuator_ctrllimited[a]):
            u[a] = float(np.clip(u[a], *mj.actuator_ctrlrange[a]))
    ids = np.asarray(result.actuator_ids, dtype=int)
    return u, u[ids].copy()


def mjcf_drop_setup(
    path: Path,
    out_dir: Path,
    dt: float,
    integrator: str = "bdf2",
    *,
    drop_height: float = 0.05,
    mujoco_integrator: str = "RK4",
    kappa: float = KAPPA,
    settings: dict | None = None,
    perturb_mass: dict[str, float] | None = None,
    perturb_anchor: dict[str, float] | None = None,
    perturb_axis: dict[str, float] | None = None,
    **unsupported,
) -> DropSetup:
    """Both simulators' floating MJCF robot at its stance, ``drop_height`` above the ground,
    holding it; the ``perturb_*`` wrong models and ``settings`` are abdsim's only
    (``robot_drop.drop_setup``).

    Raises:
        ValueError: an option that only a URDF drop has (the file's own actuators, friction
            and contact filter are used), no free root, no ground plane.
    """
    import mujoco

    from abdsim.bridges.robot_world import RobotWorld
    from abdsim.validation.robot_setup import articulate

    if unsupported:
        raise ValueError(
            f"{path}: {sorted(unsupported)} apply to a URDF drop; an MJCF robot keeps its "
            "file's actuators, friction and contact filter"
        )
    out_dir.mkdir(parents=True, exist_ok=True)
    first = _load(path, kappa)
    if not first.grounds:
        raise ValueError(f"{path}: a floating MJCF robot is dropped on its floor; it has none")
    twin = mjcf_twin(path, out_dir, drop_height - lowest_point(first))
    result = _load(twin, kappa)
    wrong = (perturb_mass, perturb_anchor, perturb_axis)
    scene = articulate(result, *wrong, dt=dt, integrator=integrator, **(settings or {}))
    world = RobotWorld(scene, result.actuators)
    (free,) = [j for j in result.joints if j.type == "free"]

    mj = mujoco.MjModel.from_xml_path(str(twin))
    mj.opt.timestep = dt
    mj.opt.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{mujoco_integrator.upper()}")
    data = mujoco.MjData(mj)
    if mj.nkey > 0:
        mujoco.mj_resetDataKeyframe(mj, data, 0)
    mujoco.mj_forward(mj, data)
    data.ctrl[:], world.ctrl[:] = hold_controls(mj, data, result)
    mujoco.mj_forward(mj, data)

    # The compared joints: hinges and slides, at their place in world.joint_positions().
    names, mj_q, world_q, k = [], [], [], 0
    for j in scene.joints:
        if j.kind in ("revolute", "prismatic"):
            names.append(j.name)
            mj_q.append(int(mj.jnt_qposadr[mj.joint(j.name).id]))
            world_q.append(k)
        k += j.nq
    mj_q = np.array(mj_q, dtype=int)
    _, root = free_root(mj)
    notes = [
        f"{twin.name} (beside this report) is {path.name} with its free root lifted so that "
        f"its lowest point starts {drop_height:g} m above the floor; both simulators load it, "
        "with the file's own actuators, contact filter and friction",
        f"controls holding the {'keyframe' if mj.nkey else 'qpos0'} stance: MuJoCo "
        f"{np.round(data.ctrl, 4).tolist()}, abdsim {np.round(world.ctrl, 4).tolist()}",
    ]
    if [j for j in scene.joints if j.kind not in ("revolute", "prismatic")]:
        notes.append("ball joints are simulated but not in the stance comparison")
    return DropSetup(
        result, scene, world, mj, data, free.child, root, data.qpos[mj_q].copy(), names, mj_q,
        None, None, f"{'keyframe 0' if mj.nkey else 'qpos0'} of {path.name}", twin, notes,
        np.array(world_q, dtype=int),
    )  # fmt: skip
