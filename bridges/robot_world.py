"""The World of a loaded robot: ``world.ctrl`` in MuJoCo's actuator order, site actuators.

``result.make_world()`` of an articulated load returns a :class:`RobotWorld`, an
``abdsim.World`` whose ``ctrl`` holds one control per actuator abdsim models
(``result.actuators``; ``result.actuator_ids`` are their MuJoCo ids): joint actuators are the
scene's (``Scene.add_actuator``), site actuators (thrusters) push their body through
``apply_wrench`` with the force along the site's current axes, set before every step from
the state at its start.
"""

from __future__ import annotations

from typing import Any

import numpy as np

import abdsim
from abdsim.sim import pose as pose_math


class RobotWorld(abdsim.World):
    """An ``abdsim.World`` with MJCF actuators of every modelled transmission on ``ctrl``.

    Args:
        scene: the articulated scene (``result.scene``).
        actuators: ``result.actuators`` (``ActuatorInfo``, MuJoCo order); the scene's
            actuators must be its joint actuators, in the same order.
    """

    def __init__(self, scene: Any, actuators: list) -> None:
        super().__init__(scene)
        self._actuators = list(actuators)
        self._ctrl = np.zeros(len(self._actuators))
        self._joint_slots = np.array(
            [k for k, a in enumerate(self._actuators) if a.kind != "site"], dtype=np.int64
        )
        if len(self._joint_slots) != len(scene.actuators):  # pragma: no cover - built together
            raise ValueError("RobotWorld: the scene's actuators are not result.actuators'")
        sites = [(k, a) for k, a in enumerate(self._actuators) if a.kind == "site"]
        self._site_slots = np.array([k for k, _ in sites], dtype=np.int64)
        self._site_body = np.array([a.body for _, a in sites], dtype=np.int64)
        self._site_pos = np.array([a.site_pos for _, a in sites]).reshape(-1, 3)
        # Force and torque directions per unit actuator force, in the body frame.
        rot = np.array([a.site_rot for _, a in sites]).reshape(-1, 3, 3)
        gear = np.array([a.gear6 for _, a in sites]).reshape(-1, 6)
        self._site_force_dir = np.einsum("kij,kj->ki", rot, gear[:, :3])
        self._site_torque_dir = np.einsum("kij,kj->ki", rot, gear[:, 3:])
        inf = np.inf
        self._site_gain = np.array([a.gain for _, a in sites])
        self._site_bias = np.array([a.bias for _, a in sites])
        self._site_ctrl_range = np.array(
            [a.ctrl_range if a.ctrl_range is not None else (-inf, inf) for _, a in sites]
        ).reshape(-1, 2)
        self._site_force_range = np.array(
            [a.force_range if a.force_range is not None else (-inf, inf) for _, a in sites]
        ).reshape(-1, 2)
        self._site_bodies = np.unique(self._site_body)
        core = self.core.scene
        self._com = {
            int(b): np.asarray(core.body(int(b)).mass_x_bar) / float(core.body(int(b)).mass)
            for b in self._site_bodies
        }

    @property
    def ctrl(self) -> np.ndarray:
        """Controls of the modelled actuators (MuJoCo order, ``result.actuator_ids``), a
        writable array: ``world.ctrl[:] = data.ctrl[result.actuator_ids]``."""
        return self._ctrl

    def site_wrenches(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(bodies, forces, torques about their centres of mass) the site actuators apply for
        the current ``ctrl`` and state, one row per pushed body (world frame)."""
        u = np.clip(self._ctrl[self._site_slots], *self._site_ctrl_range.T)
        force = np.clip(self._site_gain * u + self._site_bias, *self._site_force_range.T)
        T = self.transforms()[self._site_body]
        A = T[:, :3, :3]
        R = pose_math.nearest_rotations(A)
        points = T[:, :3, 3] + np.einsum("kij,kj->ki", A, self._site_pos)
        f = np.einsum("kij,kj->ki", R, self._site_force_dir) * force[:, None]
        tau = np.einsum("kij,kj->ki", R, self._site_torque_dir) * force[:, None]
        forces, torques = [], []
        for b in self._site_bodies:
            k = self._site_body == b
            Tb = T[np.argmax(k)]
            centre = Tb[:3, 3] + Tb[:3, :3] @ self._com[int(b)]
            forces.append(f[k].sum(axis=0))
            torques.append(tau[k].sum(axis=0) + np.cross(points[k] - centre, f[k]).sum(axis=0))
        return self._site_bodies, np.array(forces), np.array(torques)

    def _before_step(self) -> None:
        if len(self._joint_slots):
            abdsim.World.ctrl.fget(self)[:] = self._ctrl[self._joint_slots]
        if len(self._site_slots):
            for b, f, t in zip(*self.site_wrenches(), strict=True):
                self.apply_wrench(int(b), f, t)

    def step(self, n: int = 1, progress: bool = False, log: Any = None):
        """As ``abdsim.World.step``; the site actuators' wrenches follow the bodies' axes
        step by step (with site actuators the steps run one at a time)."""
        self._before_step()
        if not len(self._site_slots) or not isinstance(n, (int, np.integer)) or n <= 1:
            return super().step(n, progress=progress, log=log)
        diagnostics = super().step(1, log=log)
        for _ in range(int(n) - 1):
            self._before_step()
            diagnostics = super().step(1, log=log)
        return diagnostics
