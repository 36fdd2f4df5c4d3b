"""Values of the joint sensors (jointpos, jointvel, actuatorfrc; abdsim.sim.sensors) at a
World's state, from its joint coordinates and actuators."""

from __future__ import annotations

import numpy as np

from abdsim.sim.joints import ActuatorHandle, JointHandle
from abdsim.sim.sensors import JOINT_TYPES, SensorSpec


def actuator_force(a: ActuatorHandle, u: float, theta: float, rate: float) -> float:
    """MuJoCo's general actuator with the motor / position / velocity presets, as abdsim's
    joint force term applies it: gain·u + b0 + b1·L + b2·L̇ with L = gear θ, the control and the
    force clamped to their ranges."""
    if a.ctrl_range is not None:
        u = float(np.clip(u, *a.ctrl_range))
    gain, b1, b2 = 1.0, 0.0, 0.0
    if a.kind == "position":
        gain, b1, b2 = a.kp, -a.kp, -a.kv
    elif a.kind == "velocity":
        gain, b2 = a.kv, -a.kv
    force = gain * u + a.bias + b1 * a.gear * theta + b2 * a.gear * rate
    if a.force_range is not None:
        force = float(np.clip(force, *a.force_range))
    return force


def joint_sensor_values(
    specs: list[SensorSpec],
    joints: list[JointHandle],
    positions: np.ndarray,
    velocities: np.ndarray,
    actuators: list[ActuatorHandle],
    ctrl: np.ndarray,
) -> dict[int, float]:
    """{sensor index: value} of the joint sensors in ``specs``; NaN where the sensor's joint
    or actuator is not there (or is not a 1-dof joint)."""
    q_adr, v_adr = {}, {}
    qa = va = 0
    for j in joints:
        q_adr[j.name], v_adr[j.name] = (qa, va) if j.nq == 1 else (None, None)
        qa, va = qa + j.nq, va + j.nv
    out: dict[int, float] = {}
    for i, s in enumerate(specs):
        if s.type not in JOINT_TYPES:
            continue
        value = np.nan
        if s.type == "jointpos" and q_adr.get(s.joint) is not None:
            value = s.offset + float(positions[q_adr[s.joint]])
        elif s.type == "jointvel" and v_adr.get(s.joint) is not None:
            value = float(velocities[v_adr[s.joint]])
        elif s.type == "actuatorfrc" and 0 <= s.actuator < len(actuators):
            a = actuators[s.actuator]
            name = joints[a.joint].name
            value = s.gain * actuator_force(
                a, float(ctrl[s.actuator]), positions[q_adr[name]], velocities[v_adr[name]]
            )
        if s.cutoff > 0 and np.isfinite(value):
            value = float(np.clip(value, -s.cutoff, s.cutoff))
        out[i] = value
    return out
