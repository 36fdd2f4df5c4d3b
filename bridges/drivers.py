"""Kinematic drivers: move a loaded scene's kinematic bodies along a joint trajectory.

A driver evaluates the source's own forward kinematics (Pinocchio for URDF, MuJoCo for MJCF)
at ``q(t)`` and gives every kinematic body its world target pose and velocity (dT/dt). A
kinematic body that hangs below a *dynamic* body (a limb of a floating-base robot) is placed
relative to that body's current simulated pose: the limb follows the simulated base, but (no
joint energies yet) does not push it.

``q(t)`` is a callable ``t -> q`` or samples ``(T, nq)`` with their ``times`` (or a uniform
``dt`` from t = 0); between samples the driver interpolates on the configuration manifold
(``integrate(q_i, s · difference(q_i, q_{i+1}))``), outside it holds the end values.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from abdsim.bridges._bodies import LoadResult, skew, velocity_matrix
from abdsim.bridges.urdf import joint_kinematics

# Above this many DOF, RobotDriver does not allocate a pinocchio.Data (see RobotDriver).
_DATA_MAX_NV = 64

Trajectory = Callable[[float], np.ndarray] | np.ndarray | Sequence[Sequence[float]]


class KinematicDriver:
    """Targets of a :class:`LoadResult`'s kinematic bodies along a joint trajectory.

    Args:
        result: the loaded scene.
        trajectory: a callable ``t -> q`` or an array of configurations ``(T, nq)``.
        times: sample times (T,), strictly increasing, for an array trajectory.
        dt: uniform sample spacing from t = 0 (instead of ``times``).
        body_offset: index of ``result.bodies[0]`` in the World (0 when the scene was built
            from ``result`` alone).

    Attributes:
        bodies: result body indices this driver moves (the kinematic ones).
    """

    #: Step for the central difference that gives a callable trajectory's velocity.
    fd_step = 1e-6

    def __init__(
        self,
        result: LoadResult,
        trajectory: Trajectory,
        *,
        times: Sequence[float] | None = None,
        dt: float | None = None,
        body_offset: int = 0,
    ) -> None:
        self.result = result
        self.bodies = result.indices("kinematic")
        self.body_offset = int(body_offset)
        self._callable: Callable[[float], np.ndarray] | None = None
        if callable(trajectory):
            self._callable = trajectory
            self._samples = self._times = None
        else:
            samples = np.asarray(trajectory, dtype=np.float64)
            if samples.ndim == 1:
                samples = samples[None]
            if samples.ndim != 2 or samples.shape[1] != self.nq:
                raise ValueError(
                    f"trajectory must have shape (T, {self.nq}) for this model, got "
                    f"{np.shape(trajectory)}"
                )
            if not np.isfinite(samples).all():
                raise ValueError("trajectory contains NaN or infinite values")
            if times is None:
                if dt is None:
                    if len(samples) > 1:
                        raise ValueError("give the samples' times= or a uniform dt=")
                    dt = 1.0
                if not (np.isfinite(dt) and dt > 0):
                    raise ValueError(f"dt must be positive, got {dt}")
                times = np.arange(len(samples)) * float(dt)
            t = np.asarray(times, dtype=np.float64).reshape(-1)
            if t.shape != (len(samples),):
                raise ValueError(f"times must have {len(samples)} entries, got {t.size}")
            if not np.isfinite(t).all() or (np.diff(t) <= 0).any():
                raise ValueError("times must be finite and strictly increasing")
            self._samples, self._times = samples, t

    # -- model-specific hooks (subclasses) ---------------------------------------------------
    @property
    def nq(self) -> int:
        raise NotImplementedError

    def _difference(self, q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _integrate(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _kinematics(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World pose and dT/dt of every body of the result, each (n, 4, 4)."""
        raise NotImplementedError

    # -- trajectory -----------------------------------------------------------------------------
    def configuration(self, t: float) -> np.ndarray:
        """q(t)."""
        return self.state(t)[0]

    def state(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(q(t), joint velocity v(t))."""
        t = float(t)
        if self._callable is not None:
            q = self._checked(self._callable(t))
            h = self.fd_step
            v = self._difference(
                self._checked(self._callable(t - h)), self._checked(self._callable(t + h))
            )
            return q, v / (2 * h)
        times, samples = self._times, self._samples
        if t <= times[0] or len(times) == 1:
            return samples[0].copy(), np.zeros_like(self._difference(samples[0], samples[0]))
        if t >= times[-1]:
            return samples[-1].copy(), np.zeros_like(self._difference(samples[0], samples[0]))
        i = int(np.searchsorted(times, t, side="right")) - 1
        span = times[i + 1] - times[i]
        dq = self._difference(samples[i], samples[i + 1])
        s = (t - times[i]) / span
        q = samples[i].copy() if s == 0 else self._integrate(samples[i], s * dq)
        return q, dq / span

    def _checked(self, q: Any) -> np.ndarray:
        arr = np.asarray(q, dtype=np.float64).reshape(-1)
        if arr.shape != (self.nq,) or not np.isfinite(arr).all():
            raise ValueError(f"trajectory returned {np.shape(q)} values; expected {self.nq} finite")
        return arr

    # -- targets ----------------------------------------------------------------------------------
    def targets(
        self,
        t: float,
        anchor_transforms: np.ndarray | None = None,
        anchor_velocities: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """World target pose and dT/dt of each body in :attr:`bodies`, each (k, 4, 4).

        ``anchor_transforms`` / ``anchor_velocities``: the current simulated poses and dT/dt
        of all of ``result``'s bodies (result order). Needed only when a kinematic body hangs
        below a dynamic one; it is then placed relative to that body's simulated pose.
        """
        q, v = self.state(t)
        poses, rates = self._kinematics(q, v)
        out_T = np.empty((len(self.bodies), 4, 4))
        out_V = np.empty((len(self.bodies), 4, 4))
        for k, i in enumerate(self.bodies):
            a = self._dynamic_anchor(i)
            if a is None:
                out_T[k], out_V[k] = poses[i], rates[i]
                continue
            if anchor_transforms is None:
                raise ValueError(
                    f"body {self.result.bodies[i].name!r} hangs below the dynamic body "
                    f"{self.result.bodies[a].name!r}: pass the simulated anchor_transforms"
                )
            Ta_sim = np.asarray(anchor_transforms[a])
            Va_sim = np.zeros((4, 4)) if anchor_velocities is None else anchor_velocities[a]
            inv_a = np.linalg.inv(poses[a])
            X = inv_a @ poses[i]
            X_dot = inv_a @ rates[i] - inv_a @ rates[a] @ X
            out_T[k] = Ta_sim @ X
            out_V[k] = Va_sim @ X + Ta_sim @ X_dot
        return out_T, out_V

    def _dynamic_anchor(self, i: int) -> int | None:
        p = self.result.bodies[i].parent
        while p is not None:
            if self.result.bodies[p].kind == "dynamic":
                return p
            p = self.result.bodies[p].parent
        return None

    def _world_targets(self, world: Any, t: float) -> np.ndarray:
        from abdsim.bridges import _world_adapter as adapter

        anchors = velocities = None
        if any(self._dynamic_anchor(i) is not None for i in self.bodies):
            n, off = len(self.result.bodies), self.body_offset
            velocities = adapter.world_velocities(world)[off : off + n]
            # Predict the dynamic anchors at t (the end of the step) with their velocity.
            lead = t - adapter.world_time(world)
            anchors = predict_poses(
                adapter.world_transforms(world)[off : off + n], velocities, lead
            )
        return self.targets(t, anchors, velocities)[0]

    def apply(self, world: Any, t: float | None = None) -> None:
        """Set the World's kinematic targets: the poses at ``t``, the end of the next step.

        ``t`` defaults to ``world.time + dt``. Call before every ``world.step()`` (or use
        :meth:`attach` once).
        """
        from abdsim.bridges import _world_adapter as adapter

        if t is None:
            t = adapter.world_time(world) + adapter.world_dt(world)
        T = self._world_targets(world, t)
        bodies = [self.body_offset + i for i in self.bodies]
        adapter.set_kinematic_targets(world, bodies, T, np.zeros_like(T))

    def attach(self, world: Any) -> None:
        """Drive the World's kinematic bodies on every step from now on (kinematic schedules).

        Forward kinematics runs once per step for all the bodies.
        """
        from abdsim.bridges import _world_adapter as adapter

        cache: dict[str, Any] = {"t": None, "T": None}

        def schedule_of(k: int):
            def schedule(t: float) -> np.ndarray:
                if cache["t"] != t:
                    cache["T"], cache["t"] = self._world_targets(world, t), t
                return cache["T"][k]

            return schedule

        for k, i in enumerate(self.bodies):
            adapter.set_kinematic_schedule(world, self.body_offset + i, schedule_of(k))


def predict_poses(T: np.ndarray, V: np.ndarray, lead: float) -> np.ndarray:
    """Poses ``lead`` seconds ahead at constant twist: p + lead·ṗ, exp(lead·[ω]×) A."""
    out = np.array(T, dtype=np.float64)
    for i in range(len(out)):
        A, A_dot = out[i, :3, :3], V[i, :3, :3]
        W = A_dot @ np.linalg.inv(A)
        w = 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]]) * lead
        angle = float(np.linalg.norm(w))
        K = skew(w)
        if angle < 1e-12:
            R = np.eye(3) + K
        else:
            R = np.eye(3) + np.sin(angle) / angle * K + (1 - np.cos(angle)) / angle**2 * K @ K
        out[i, :3, :3] = R @ A
        out[i, :3, 3] += lead * V[i, :3, 3]
    return out


class RobotDriver(KinematicDriver):
    """Kinematic driver of a URDF robot (``load_urdf``) through Pinocchio's kinematics.

    ``q`` has Pinocchio's layout (``model.nq``; a free-flyer root is ``[x, y, z, qx, qy, qz,
    qw]``, its values only matter as the FK reference frame of the limbs).
    """

    def __init__(self, result: LoadResult, trajectory: Trajectory, **kwargs: Any) -> None:
        import pinocchio as pin

        if result.format != "urdf":
            raise ValueError("RobotDriver drives a URDF result (use MjcfDriver for MJCF)")
        self._pin = pin
        self._model = result.model
        # pinocchio.Data holds buffers for every algorithm and grows with the cube of the
        # joint count (0.5 GB at 200 joints, 4 GB at 400): large trees take the one-pass
        # kinematics of the loader (a Python loop over joints) instead.
        self._data = result.model.createData() if result.model.nv <= _DATA_MAX_NV else None
        super().__init__(result, trajectory, **kwargs)

    @property
    def nq(self) -> int:
        return int(self._model.nq)

    def _difference(self, q0, q1):
        return np.array(self._pin.difference(self._model, q0, q1))

    def _integrate(self, q, v):
        return np.array(self._pin.integrate(self._model, q, v))

    def _kinematics(self, q, v):
        if self._data is not None:
            self._pin.forwardKinematics(self._model, self._data, q, v)
            placements, velocities = self._data.oMi, self._data.v
        else:
            placements, velocities, _ = joint_kinematics(self._pin, self._model, q, v)
        n = len(self.result.bodies)
        poses, rates = np.tile(np.eye(4), (n, 1, 1)), np.zeros((n, 4, 4))
        for j, i in self.result.source_map.items():
            oMi = placements[j]
            R = np.array(oMi.rotation)
            poses[i] = oMi.homogeneous
            vj = velocities[j]
            rates[i] = velocity_matrix(R, R @ vj.angular, R @ vj.linear)
        return poses, rates


class MjcfDriver(KinematicDriver):
    """Kinematic driver of an MJCF scene (``load_mjcf``) through MuJoCo's kinematics.

    ``q`` is a full ``qpos`` (``model.nq``); the entries of free joints only matter as the FK
    reference frame of bodies below them.
    """

    def __init__(self, result: LoadResult, trajectory: Trajectory, **kwargs: Any) -> None:
        import mujoco

        if result.format != "mjcf":
            raise ValueError("MjcfDriver drives an MJCF result (use RobotDriver for URDF)")
        self._mj = mujoco
        self._model = result.model
        self._data = mujoco.MjData(result.model)
        super().__init__(result, trajectory, **kwargs)

    @property
    def nq(self) -> int:
        return int(self._model.nq)

    def _difference(self, q0, q1):
        v = np.zeros(self._model.nv)
        self._mj.mj_differentiatePos(self._model, v, 1.0, q0, q1)
        return v

    def _integrate(self, q, v):
        out = np.array(q, dtype=np.float64)
        self._mj.mj_integratePos(self._model, out, v, 1.0)
        return out

    def _kinematics(self, q, v):
        m, d, mj = self._model, self._data, self._mj
        d.qpos[:] = q
        d.qvel[:] = v
        mj.mj_kinematics(m, d)
        mj.mj_comPos(m, d)
        mj.mj_comVel(m, d)
        n = len(self.result.bodies)
        poses, rates = np.tile(np.eye(4), (n, 1, 1)), np.zeros((n, 4, 4))
        res = np.zeros(6)
        for b, i in self.result.source_map.items():
            R = np.array(d.xmat[b]).reshape(3, 3)
            poses[i, :3, :3], poses[i, :3, 3] = R, d.xpos[b]
            mj.mj_objectVelocity(m, d, mj.mjtObj.mjOBJ_XBODY, b, res, 0)
            rates[i] = velocity_matrix(R, res[:3], res[3:])
        return poses, rates
