"""MJCF fixed tendons that move one joint: the actuator transmission abdsim can model.

A ``<fixed>`` tendon's length is ``L = Σ coef_i q_i`` and an actuator on it pushes each joint
with ``coef_i`` times its force. When exactly one coefficient is non-zero (dm_control's
``point_mass`` drives each slide through its own tendon this way) the tendon *is* that joint
scaled by ``coef``: an actuator with gear ``g`` on it is a joint actuator with gear
``g·coef`` (same length, same moment), so abdsim models it exactly. The tendon's own physics
(stiffness, damping, limits) stays unsimulated and named in the notes
(``bridges/_mjcf_unsupported.py``).
"""

from __future__ import annotations


def tendon_joint(mujoco, model, tendon: int) -> tuple[int, float, str | None]:
    """``(joint id, coef, None)`` of a fixed tendon that moves exactly one joint, else
    ``(-1, 0.0, why not)``."""
    name = model.tendon(tendon).name or f"tendon{tendon}"
    adr, num = int(model.tendon_adr[tendon]), int(model.tendon_num[tendon])
    joint_wrap = int(mujoco.mjtWrap.mjWRAP_JOINT)
    if any(int(model.wrap_type[w]) != joint_wrap for w in range(adr, adr + num)):
        return -1, 0.0, f"its tendon {name!r} is spatial (only fixed tendons are modelled)"
    moved = [
        (int(model.wrap_objid[w]), float(model.wrap_prm[w]))
        for w in range(adr, adr + num)
        if float(model.wrap_prm[w]) != 0.0
    ]
    if len(moved) != 1:
        why = f"its fixed tendon {name!r} couples {len(moved)} joints (modelled: one joint)"
        return -1, 0.0, why
    return moved[0][0], moved[0][1], None


def transmission_only(mujoco, model, tendon: int) -> bool:
    """Whether a tendon moves one joint and has no physics of its own (stiffness, damping,
    friction loss, armature, limits): then it is only an actuator transmission, modelled
    exactly."""
    t = tendon
    armature = getattr(model, "tendon_armature", None)  # newer MuJoCo only
    return (
        (armature is None or float(armature[t]) == 0.0)
        and tendon_joint(mujoco, model, t)[2] is None
        and not int(model.tendon_limited[t])
        and float(model.tendon_stiffness[t]) == 0.0
        and float(model.tendon_damping[t]) == 0.0
        and float(model.tendon_frictionloss[t]) == 0.0
    )
