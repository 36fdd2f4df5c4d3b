"""MJCF actuators as abdsim actuators: what each MuJoCo actuator becomes, and why not.

MuJoCo's actuator force is ``gain·u + b0 + b1·L + b2·L̇`` (``gaintype="fixed"``,
``biastype="affine"``; ``motor``, ``position``, ``velocity`` are presets of it), with the
control ``u`` clamped to ``ctrlrange`` and the force to ``forcerange``; a joint transmission
gives the joint ``gear·force`` with ``L = gear·θ``.

* **Joint transmission** (hinge, slide): abdsim's actuators are the motor / position /
  velocity presets. Any affine actuator with ``b0 = 0``, ``b1 <= 0``, ``b2 <= 0`` *is* one of
  them after rescaling the gear by ``s``: with ``gear' = s·gear``, ``kp = g/s``, ``kv =
  −b2/s²`` and ``forcerange' = forcerange/s`` the joint gets exactly MuJoCo's force (position:
  ``s = −b1/g``; velocity, ``b1 = 0``: ``s = −b2/g``, gain ``g/s``; motor: ``s = g``). The
  control is MuJoCo's, unscaled.
* **Site transmission** on a moving body (thrusters): force ``clamp(g·u + b0)`` along the
  site-frame ``gear[:3]`` at the site, torque along ``gear[3:]``; applied by the
  :class:`abdsim.bridges.RobotWorld` of ``result.make_world()`` before every step.
* **Fixed tendon moving one joint** (``bridges/_mjcf_tendons.py``): that joint's actuator with
  the gear times the tendon's coefficient.
* Not modelled, each named in the notes and left out of ``world.ctrl`` (``result.actuator_ids``
  says which MuJoCo actuator each entry of ``world.ctrl`` is): other tendons, slider-crank, body
  (adhesion) transmissions, a ``refsite``, actuators on ball or free joints, activation
  dynamics (``dyntype`` filter, integrator, muscle...), non-fixed gains, muscle / user biases,
  a constant bias ``b0`` or a destabilising ``b1``/``b2 > 0`` on a joint, velocity bias on a
  site.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from abdsim.bridges._mjcf_tendons import tendon_joint


@dataclass
class ActuatorInfo:
    """One MuJoCo actuator abdsim models.

    Attributes:
        name: the actuator's name (``actuator<i>`` when unnamed).
        mj_id: its MuJoCo actuator id (index into ``MjData.ctrl``).
        kind: ``"motor"``, ``"position"``, ``"velocity"`` (a joint) or ``"site"``.
        joint: the joint's name (joint transmissions, or the one joint a fixed tendon moves).
        kp, kv, gear: abdsim's preset gains and (rescaled) gear (joint transmissions).
        ctrl_range: MuJoCo's ``ctrlrange`` when ``ctrllimited``, else None.
        force_range: the force range abdsim applies (rescaled by the gear factor for joints).
        body: the loaded body a site actuator pushes.
        site_pos, site_rot: the site's pose in that body's frame (site actuators).
        gear6: MuJoCo's 6-vector gear, in the site frame (site actuators).
        gain, bias: ``gain·u + bias`` is a site actuator's force before ``force_range``.
    """

    name: str
    mj_id: int
    kind: str
    joint: str | None = None
    kp: float = 0.0
    kv: float = 0.0
    gear: float = 1.0
    ctrl_range: tuple[float, float] | None = None
    force_range: tuple[float, float] | None = None
    body: int | None = None
    site_pos: np.ndarray | None = None
    site_rot: np.ndarray | None = None
    gear6: np.ndarray | None = None
    gain: float = 1.0
    bias: float = 0.0


def _enum(mujoco, enum: str, value: int, prefix: str) -> str:
    return getattr(mujoco, enum)(int(value)).name[len(prefix) :].lower()


def _scaled_range(r: tuple[float, float] | None, s: float) -> tuple[float, float] | None:
    if r is None:
        return None
    a, b = r[0] / s, r[1] / s
    return (min(a, b), max(a, b))


def _joint_preset(g: float, b0: float, b1: float, b2: float) -> tuple[str, float, float, float]:
    """(kind, s, kp, kv) of the abdsim preset equal to ``g·u + b0 + b1·L + b2·L̇``, or raise
    ValueError saying why there is none."""
    if g == 0.0:
        raise ValueError("its gain is zero (a bias-only actuator)")
    if b0 != 0.0:
        raise ValueError(f"a constant bias b0 = {b0:g} has no abdsim actuator preset")
    if b1 > 0.0 or b2 > 0.0:
        raise ValueError(f"a destabilising bias (b1 = {b1:g}, b2 = {b2:g}) is not modelled")
    if b1 < 0.0:
        s = -b1 / g
        return "position", s, g / s, -b2 / (s * s)
    if b2 < 0.0:
        s = -b2 / g
        return "velocity", s, 0.0, g / s
    return "motor", g, 0.0, 0.0


def _site_pose_in_body(loader_pose, model, site: int, root: int) -> tuple[np.ndarray, np.ndarray]:
    from abdsim.bridges._bodies import pose_matrix, quat_wxyz_to_matrix

    X = loader_pose(int(model.site_bodyid[site]), root) @ pose_matrix(
        quat_wxyz_to_matrix(model.site_quat[site]), model.site_pos[site]
    )
    return X[:3, 3].copy(), X[:3, :3].copy()


def read_actuators(mujoco, model, source_map, body_pose_in_root, loaded_joints, notes):
    """The actuators abdsim models (MuJoCo order) and a note for every one it does not.

    ``source_map``: weld-root body id -> loaded body index; ``body_pose_in_root(b, root)``: a
    body's pose in its weld root's frame; ``loaded_joints``: names of the joints that became
    abdsim joints (the others' actuators are left out with a note).
    """
    out: list[ActuatorInfo] = []
    for a in range(model.nu):
        name = model.actuator(a).name or f"actuator{a}"
        ctrl = tuple(float(x) for x in model.actuator_ctrlrange[a])
        force = tuple(float(x) for x in model.actuator_forcerange[a])
        ctrl_range = ctrl if int(model.actuator_ctrllimited[a]) else None
        force_range = force if int(model.actuator_forcelimited[a]) else None
        trn = _enum(mujoco, "mjtTrn", model.actuator_trntype[a], "mjTRN_")
        dyn = _enum(mujoco, "mjtDyn", model.actuator_dyntype[a], "mjDYN_")
        gain = _enum(mujoco, "mjtGain", model.actuator_gaintype[a], "mjGAIN_")
        bias = _enum(mujoco, "mjtBias", model.actuator_biastype[a], "mjBIAS_")
        g = float(model.actuator_gainprm[a, 0])
        b0, b1, b2 = (float(x) for x in model.actuator_biasprm[a, :3])
        if bias == "none":
            b0 = b1 = b2 = 0.0
        target = int(model.actuator_trnid[a, 0])
        why, tendon_why, coef = None, None, 1.0
        if trn == "tendon":  # a fixed tendon on one joint is that joint (bridges/_mjcf_tendons)
            joint_id, coef, tendon_why = tendon_joint(mujoco, model, target)
            if tendon_why is None:
                trn, target = "joint", joint_id
        if dyn != "none":
            why = f"activation dynamics dyntype={dyn!r} are not modelled"
        elif gain != "fixed":
            why = f"gaintype={gain!r} is not modelled (only fixed gains)"
        elif bias not in ("none", "affine"):
            why = f"biastype={bias!r} is not modelled (only affine biases)"
        elif trn in ("joint", "jointinparent"):
            joint = model.joint(target).name or f"joint{target}"
            jtype = _enum(mujoco, "mjtJoint", model.jnt_type[target], "mjJNT_")
            if jtype not in ("hinge", "slide"):
                why = f"it drives {jtype} joint {joint!r} (abdsim drives hinges and slides)"
            elif joint not in loaded_joints:
                why = f"its joint {joint!r} is not an abdsim joint of this scene"
            else:
                try:
                    kind, s, kp, kv = _joint_preset(g, b0, b1, b2)
                except ValueError as e:
                    why = str(e)
                else:
                    gear = float(model.actuator_gear[a, 0]) * coef * s
                    out.append(
                        ActuatorInfo(
                            name, a, kind, joint=joint, kp=kp, kv=kv, gear=gear,
                            ctrl_range=ctrl_range, force_range=_scaled_range(force_range, s),
                        )
                    )  # fmt: skip
        elif trn == "site":
            root = int(model.body_weldid[int(model.site_bodyid[target])])
            if int(model.actuator_trnid[a, 1]) >= 0:
                why = "a site transmission with a refsite is not modelled"
            elif b1 != 0.0 or b2 != 0.0:
                why = "a length or velocity bias on a site transmission is not modelled"
            elif root not in source_map:
                why = f"its site {model.site(target).name!r} is on no moving loaded body"
            else:
                pos, rot = _site_pose_in_body(body_pose_in_root, model, target, root)
                out.append(
                    ActuatorInfo(
                        name, a, "site", ctrl_range=ctrl_range, force_range=force_range,
                        body=source_map[root], site_pos=pos, site_rot=rot,
                        gear6=np.array(model.actuator_gear[a], dtype=np.float64), gain=g, bias=b0,
                    )
                )  # fmt: skip
        else:
            why = tendon_why or f"{trn} transmission is not modelled"
        if why is not None:
            notes.append(f"actuator {name!r}: not simulated, {why}; it is not in world.ctrl")
    sites = [a.name for a in out if a.kind == "site"]
    if sites:  # a World built straight from result.scene would silently lack them
        notes.append(
            f"site actuators {sites}: applied by result.make_world() (abdsim.bridges.RobotWorld) "
            "before each step; an abdsim.World built from result.scene has only the joint "
            "actuators on its ctrl"
        )
    return out


def add_actuators(scene, result) -> None:
    """Add the joint actuators of ``result.actuators`` to ``scene`` (MuJoCo order)."""
    for info in result.actuators:
        if info.kind == "site":
            continue
        scene.add_actuator(
            info.joint,
            info.kind,
            kp=info.kp,
            kv=info.kv,
            gear=info.gear,
            ctrl_range=info.ctrl_range,
            force_range=info.force_range,
        )
