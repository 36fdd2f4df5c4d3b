"""Runs a scene in MuJoCo and records it as a Trajectory.

The free bodies are the ones compared. MuJoCo is run with RK4 (or the model's integrator if
asked) at the requested step; energy is enabled so ``data.energy`` can be reported as well.
"""

from __future__ import annotations

import time
from pathlib import Path

import mujoco
import numpy as np

from abdsim.validation.trajectory import Recorder, Trajectory


def load_model(path: str | Path) -> mujoco.MjModel:
    """MjModel from an MJCF or URDF file, with MuJoCo's error turned into a ValueError."""
    try:
        return mujoco.MjModel.from_xml_path(str(path))
    except ValueError as err:  # mujoco raises ValueError with the XML error
        raise ValueError(f"MuJoCo rejected {path}: {err}") from err


def free_bodies(model: mujoco.MjModel) -> list[int]:
    """Ids of bodies whose first joint is a free joint."""
    out = []
    for b in range(1, model.nbody):
        j = model.body_jntadr[b]
        if j >= 0 and model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            out.append(b)
    return out


def initial_data(model: mujoco.MjModel, keyframe: int | None) -> mujoco.MjData:
    """MjData at the keyframe (if the model has it) with kinematics computed."""
    data = mujoco.MjData(model)
    if keyframe is not None and model.nkey > keyframe:
        mujoco.mj_resetDataKeyframe(model, data, keyframe)
    mujoco.mj_forward(model, data)
    return data


def body_names(model: mujoco.MjModel, bodies: list[int]) -> list[str]:
    return [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in bodies]


def body_state(model: mujoco.MjModel, data: mujoco.MjData, bodies: list[int]) -> dict:
    """COM, rotation, COM velocity, world angular velocity and momenta of free bodies."""
    com = data.xipos[bodies].copy()
    rot = data.xmat[bodies].reshape(-1, 3, 3).copy()
    dof = model.jnt_dofadr[model.body_jntadr[bodies]]
    v_origin = np.stack([data.qvel[d : d + 3] for d in dof])
    omega_body = np.stack([data.qvel[d + 3 : d + 6] for d in dof])
    omega = np.einsum("nij,nj->ni", rot, omega_body)
    v_com = v_origin + np.cross(omega, com - data.xpos[bodies])
    mass = model.body_mass[bodies]
    ri = data.ximat[bodies].reshape(-1, 3, 3)
    inertia_world = ri @ (model.body_inertia[bodies][:, :, None] * np.swapaxes(ri, 1, 2))
    L = np.einsum("nij,nj->ni", inertia_world, omega)
    return {
        "com": com,
        "rotation": rot,
        "v_com": v_com,
        "omega": omega,
        "linear_momentum": mass[:, None] * v_com,
        "angular_momentum": L,
        "mass": mass,
    }


def run_mujoco(
    path: str | Path,
    duration: float,
    dt: float,
    sample_dt: float,
    integrator: str = "RK4",
    keyframe: int | None = 0,
) -> Trajectory:
    """Simulate ``path`` in MuJoCo for ``duration`` seconds at step ``dt``.

    The first keyframe (if any) gives the initial state. Samples every ``sample_dt``.
    """
    model = load_model(path)
    model.opt.timestep = dt
    model.opt.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{integrator.upper()}")
    model.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    data = initial_data(model, keyframe)
    bodies = free_bodies(model)
    names = body_names(model, bodies)
    gravity = model.opt.gravity.copy()
    rec = Recorder("mujoco", names)
    n_steps = int(round(duration / dt))
    every = max(1, int(round(sample_dt / dt)))
    wall = 0.0

    poses = []
    free_geom = np.isin(model.body_rootid[model.geom_bodyid], bodies)

    def sample() -> None:
        s = body_state(model, data, bodies)
        T = np.tile(np.eye(4), (len(bodies), 1, 1))
        T[:, :3, :3] = s["rotation"]
        T[:, :3, 3] = data.xpos[bodies]
        poses.append(T)
        # Only contacts that involve a compared (free) body: MuJoCo also reports contacts
        # between static and scripted geoms, which abdsim rightly ignores.
        dist = min(
            (c.dist for c in data.contact[: data.ncon] if free_geom[c.geom1] or free_geom[c.geom2]),
            default=np.nan,
        )
        rec.add_rigid(data.time, s, gravity, dist)

    def touching() -> bool:
        return any(
            c.dist <= 0.0 and (free_geom[c.geom1] or free_geom[c.geom2])
            for c in data.contact[: data.ncon]
        )

    # First contact from every step (a contact shorter than the sampling interval counts).
    first_contact = data.time if touching() else None
    sample()
    for k in range(1, n_steps + 1):
        t0 = time.perf_counter()
        mujoco.mj_step(model, data)
        wall += time.perf_counter() - t0
        if first_contact is None and data.ncon and touching():
            first_contact = data.time
        if k % every == 0:
            sample()
    return rec.finish(
        wall,
        n_steps,
        integrator=integrator,
        transforms=np.stack(poses),
        first_contact_time=float("inf") if first_contact is None else first_contact,
    )
