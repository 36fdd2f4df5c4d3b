"""Free-flight reference in Pinocchio: one free-flyer per body, RK4 on the Lie group.

Pinocchio's own semi-implicit Euler drifts energy, so the reference integrates
(q, v) with Runge–Kutta–Munthe-Kaas (RK4 on the Lie group): every position goes through
``pin.integrate`` (the exponential map of the free-flyer's SE(3)), keeping q on the manifold.
"""

from __future__ import annotations

import time

import mujoco
import numpy as np
import pinocchio as pin

from abdsim.validation.mujoco_reference import body_names, free_bodies, initial_data, load_model
from abdsim.validation.trajectory import Recorder, Trajectory


def free_flyer_model(masses, levers, inertias, names, gravity) -> pin.Model:
    """A Pinocchio model with one free-flyer per body (inertias about the COM, body frame)."""
    model = pin.Model()
    model.gravity.linear = np.asarray(gravity, dtype=float)
    for m, c, inertia, name in zip(masses, levers, inertias, names, strict=True):
        jid = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), name)
        model.appendBodyToJoint(
            jid, pin.Inertia(float(m), np.asarray(c), np.asarray(inertia)), pin.SE3.Identity()
        )
    return model


def initial_state_from_mujoco(
    mj_model: mujoco.MjModel, mj_data: mujoco.MjData, bodies: list[int]
) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio (q, v) equal to MuJoCo's free-body state (v in the body frame)."""
    q, v = [], []
    for b in bodies:
        R = mj_data.xmat[b].reshape(3, 3)
        dof = mj_model.jnt_dofadr[mj_model.body_jntadr[b]]
        quat_wxyz = mj_data.xquat[b]
        q.append(np.concatenate([mj_data.xpos[b], quat_wxyz[1:], quat_wxyz[:1]]))
        v.append(
            np.concatenate([R.T @ mj_data.qvel[dof : dof + 3], mj_data.qvel[dof + 3 : dof + 6]])
        )
    return np.concatenate(q), np.concatenate(v)


def rk4_step(
    model: pin.Model,
    data: pin.Data,
    q: np.ndarray,
    v: np.ndarray,
    h: float,
    damping: np.ndarray | None = None,
):
    """One Runge–Kutta–Munthe-Kaas step (order 4 on the Lie group) of ABA under zero
    control; ``damping`` (nv,) adds the viscous joint torque −damping·v at every stage.

    Stages live at q ⊕ u; the body velocity v_i there is pulled back to the increment u by
    the inverse right Jacobian of the exponential (``pin.dIntegrate`` w.r.t. its tangent
    argument). Without that correction a naive Lie-group RK4 is only second order.
    """

    def stage(u: np.ndarray, vv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        qq = pin.integrate(model, q, u)
        jr = pin.dIntegrate(model, q, u, pin.ArgumentPosition.ARG1)
        tau = np.zeros(model.nv) if damping is None else -damping * vv
        return np.linalg.solve(jr, vv), pin.aba(model, data, qq, vv, tau).copy()

    k1u, k1a = stage(np.zeros(model.nv), v)
    k2u, k2a = stage(0.5 * h * k1u, v + 0.5 * h * k1a)
    k3u, k3a = stage(0.5 * h * k2u, v + 0.5 * h * k2a)
    k4u, k4a = stage(h * k3u, v + h * k3a)
    q_next = pin.integrate(model, q, h / 6.0 * (k1u + 2 * k2u + 2 * k3u + k4u))
    v_next = v + h / 6.0 * (k1a + 2 * k2a + 2 * k3a + k4a)
    return q_next, v_next


def _sample(model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray) -> dict:
    pin.forwardKinematics(model, data, q, v)
    n = model.njoints - 1
    com, rot, vcom, omega, L, mass = [], [], [], [], [], []
    for j in range(1, n + 1):
        M = data.oMi[j]
        inertia = model.inertias[j]
        R = M.rotation
        vel = data.v[j]  # body-frame spatial velocity at the joint origin
        w_world = R @ vel.angular
        c_world = M.act(inertia.lever)
        v_c = R @ (vel.linear + np.cross(vel.angular, inertia.lever))
        com.append(c_world)
        rot.append(R)
        vcom.append(v_c)
        omega.append(w_world)
        L.append(R @ inertia.inertia @ vel.angular)
        mass.append(inertia.mass)
    out = {
        k: np.array(v_)
        for k, v_ in (
            ("com", com),
            ("rotation", rot),
            ("v_com", vcom),
            ("omega", omega),
            ("angular_momentum", L),
            ("mass", mass),
        )
    }
    out["linear_momentum"] = out["mass"][:, None] * out["v_com"]
    return out


def run_pinocchio_free_flight(
    path: str, duration: float, dt: float, sample_dt: float, keyframe: int | None = 0
) -> Trajectory:
    """Free flight (no contact) of the scene's free bodies, from MuJoCo's initial state.

    Mass properties are MuJoCo's (``body_mass``, ``body_ipos``, ``body_iquat``,
    ``body_inertia``), expressed in each body frame as Pinocchio expects.
    """
    mj_model = load_model(path)
    mj_data = initial_data(mj_model, keyframe)
    bodies = free_bodies(mj_model)
    names = body_names(mj_model, bodies)
    inertias = []
    for b in bodies:
        Ri = np.zeros(9)
        mujoco.mju_quat2Mat(Ri, mj_model.body_iquat[b])
        Ri = Ri.reshape(3, 3)
        inertias.append(Ri @ np.diag(mj_model.body_inertia[b]) @ Ri.T)
    gravity = mj_model.opt.gravity.copy()
    model = free_flyer_model(
        mj_model.body_mass[bodies], mj_model.body_ipos[bodies], inertias, names, gravity
    )
    data = model.createData()
    q, v = initial_state_from_mujoco(mj_model, mj_data, bodies)
    rec = Recorder("pinocchio", names)
    n_steps = int(round(duration / dt))
    every = max(1, int(round(sample_dt / dt)))

    def sample(t: float) -> None:
        s = _sample(model, data, q, v)
        rec.add_rigid(t, s, gravity, np.nan)

    sample(0.0)
    wall = 0.0
    for k in range(1, n_steps + 1):
        t0 = time.perf_counter()
        q, v = rk4_step(model, data, q, v, dt)
        wall += time.perf_counter() - t0
        if k % every == 0:
            sample(k * dt)
    return rec.finish(wall, n_steps)
