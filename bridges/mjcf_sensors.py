"""MJCF ``<sensor>`` elements as abdsim sensors (abdsim.sim.sensors), in MuJoCo's layout.

Read from the compiled model: every MuJoCo sensor becomes one ``SensorSpec`` in the same
order with the same ``sensor_dim``, so ``World.sensordata`` has MuJoCo's ``sensor_adr``.
Supported: ``touch``, ``force``, ``torque``, ``accelerometer``, ``gyro``, ``velocimeter``
(on sites) and ``framepos``, ``framequat`` (of a site, body (inertial frame), xbody, geom or
camera, optionally relative to another such frame). Their frames are expressed in the frame of
the loaded body (weld group root) the MuJoCo body belongs to. ``jointpos`` and ``jointvel`` of
hinges and slides read the joint of the same name in a scene built with
``build_articulated_scene`` (jointpos adds the loaded qpos: MuJoCo's value), ``actuatorfrc``
the loaded joint actuator the MuJoCo actuator became (``actuator_sensors``; with
``kinematic=True`` the abdsim actuator of the same index, ``Scene.add_actuator``); without them
they read NaN, and notes say so. Everything else (other types; frames on
the world or on a body that was not loaded) keeps its slot as an ``"unsupported"`` sensor (NaN
values) and is named in ``LoadResult.notes``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from abdsim.bridges._bodies import pose_matrix, quat_wxyz_to_matrix
from abdsim.sim.sensors import SENSOR_DIMS, SensorSpec

_SITE_SENSORS = {"touch", "force", "torque", "accelerometer", "gyro", "velocimeter"}
_FRAME_SENSORS = {"framepos", "framequat"}
_JOINT_SENSORS = {"jointpos", "jointvel", "actuatorfrc"}


def _enum_name(enum: Any, value: int, prefix: str) -> str:
    return enum(int(value)).name[len(prefix) :].lower()


class _Frames:
    """Poses of MuJoCo objects in the frame of the loaded body they move with."""

    def __init__(self, loader: Any, source_map: dict[int, int]) -> None:
        self.loader, self.m, self.source_map = loader, loader.m, source_map

    def local(self, objtype: str, objid: int) -> tuple[int, np.ndarray] | None:
        """(MuJoCo body, pose in that body's frame) of an object; None: not a frame."""
        m = self.m
        if objtype == "site":
            R = quat_wxyz_to_matrix(m.site_quat[objid])
            return int(m.site_bodyid[objid]), pose_matrix(R, m.site_pos[objid])
        if objtype == "geom":
            R = quat_wxyz_to_matrix(m.geom_quat[objid])
            return int(m.geom_bodyid[objid]), pose_matrix(R, m.geom_pos[objid])
        if objtype == "camera":
            R = quat_wxyz_to_matrix(m.cam_quat[objid])
            return int(m.cam_bodyid[objid]), pose_matrix(R, m.cam_pos[objid])
        if objtype == "body":  # MuJoCo's "body" frame sensors use the inertial frame
            R = quat_wxyz_to_matrix(m.body_iquat[objid])
            return objid, pose_matrix(R, m.body_ipos[objid])
        if objtype == "xbody":
            return objid, np.eye(4)
        return None

    def in_loaded_body(self, objtype: str, objid: int) -> tuple[int, np.ndarray] | str:
        """(abdsim body index, pose in its rest frame), or why there is none."""
        found = self.local(objtype, objid)
        if found is None:
            return f"a frame of type {objtype!r} is not supported"
        b, X = found
        root = int(self.m.body_weldid[b])
        if root == 0:
            return "it is fixed to the world (no loaded body moves it)"
        if root not in self.source_map:
            return f"its body {self.loader.body_name(b)!r} was not loaded (no collision geometry)"
        return self.source_map[root], self.loader.pose_in_root(b, root) @ X


def _joint_sensor(loader: Any, kind: str, name: str, objid: int) -> tuple[SensorSpec | None, str]:
    """A jointpos / jointvel / actuatorfrc sensor (and a note), or (None, why not)."""
    mj, m = loader.mj, loader.m
    if kind == "actuatorfrc":
        if loader.articulated:  # the loaded actuator's index is set by actuator_sensors below
            return SensorSpec(type=kind, body=-1, name=name, actuator=objid, dim=1, source=kind), ""
        loader.notes.append(
            f"sensor {name!r} (actuatorfrc): reads abdsim actuator {objid} "
            "(Scene.add_actuator; kinematic=True loads no actuators), NaN without it"
        )
        return SensorSpec(type=kind, body=-1, name=name, actuator=objid, dim=1, source=kind), ""
    jtype = _enum_name(mj.mjtJoint, m.jnt_type[objid], "mjJNT_")
    if jtype not in ("hinge", "slide"):
        return None, f"its joint is a {jtype} joint (only hinges and slides are read)"
    joint = m.joint(objid).name
    offset = float(loader.d.qpos[m.jnt_qposadr[objid]]) if kind == "jointpos" else 0.0
    loader.notes.append(
        f"sensor {name!r} ({kind}): reads joint {joint!r} in a scene built with "
        "build_articulated_scene, NaN otherwise"
    )
    spec = SensorSpec(type=kind, body=-1, name=name, joint=joint, offset=offset, dim=1, source=kind)
    return spec, ""


def read_sensors(loader: Any, source_map: dict[int, int]) -> list[SensorSpec]:
    """One SensorSpec per MuJoCo sensor of ``loader``'s model, in order; what cannot be
    computed becomes an ``"unsupported"`` slot and a note in ``loader.notes``."""
    mj, m = loader.mj, loader.m
    frames = _Frames(loader, source_map)
    specs: list[SensorSpec] = []
    for i in range(m.nsensor):
        kind = _enum_name(mj.mjtSensor, m.sensor_type[i], "mjSENS_")
        name = m.sensor(i).name or f"sensor{i}"
        dim = int(m.sensor_dim[i])
        objtype = _enum_name(mj.mjtObj, m.sensor_objtype[i], "mjOBJ_")
        why = None
        spec = None
        if kind in _JOINT_SENSORS:
            spec, why = _joint_sensor(loader, kind, name, int(m.sensor_objid[i]))
            if spec is not None:
                spec = SensorSpec(**{**spec.__dict__, "cutoff": float(m.sensor_cutoff[i])})
        elif kind not in SENSOR_DIMS:
            why = "this sensor type is not supported"
        else:
            where = frames.in_loaded_body(objtype, int(m.sensor_objid[i]))
            ref = None
            reftype = int(m.sensor_reftype[i])
            if isinstance(where, str):
                why = f"its {objtype} cannot be placed: {where}"
            elif kind in _FRAME_SENSORS and int(m.sensor_refid[i]) >= 0 and reftype > 0:
                ref_type = _enum_name(mj.mjtObj, reftype, "mjOBJ_")
                ref = frames.in_loaded_body(ref_type, int(m.sensor_refid[i]))
                if isinstance(ref, str):
                    why = f"its reference {ref_type} cannot be placed: {ref}"
            if why is None:
                body, X = where
                zone = None
                if kind == "touch":
                    site = int(m.sensor_objid[i])
                    shape = _enum_name(mj.mjtGeom, m.site_type[site], "mjGEOM_")
                    zone = (shape, np.array(m.site_size[site], dtype=np.float64))
                spec = SensorSpec(
                    type=kind,
                    body=body,
                    pos=X[:3, 3].copy(),
                    rot=X[:3, :3].copy(),
                    name=name,
                    zone=zone,
                    ref=None if ref is None else (ref[0], ref[1][:3, 3].copy(), ref[1][:3, :3]),
                    cutoff=float(m.sensor_cutoff[i]),
                    dim=dim,
                    source=kind,
                )
        if spec is None:
            loader.notes.append(
                f"sensor {name!r} ({kind}): not computed ({why}); its {dim} value(s) in "
                "sensordata are NaN"
            )
            spec = SensorSpec(type="unsupported", body=-1, name=name, dim=dim, source=kind)
        specs.append(spec)
    return specs


def actuator_sensors(specs: list[SensorSpec], actuators: list[Any], model: Any, notes: list[str]):
    """``specs`` with each ``actuatorfrc`` sensor (MuJoCo actuator id in ``actuator``) reading
    the abdsim joint actuator that MuJoCo actuator became (``bridges/_mjcf_actuators.py``,
    added to the scene in order, site actuators excepted), scaled back to MuJoCo's force by
    the gear rescaling s (``gain``); one whose actuator was not loaded is an unsupported slot
    with a note."""
    from dataclasses import replace

    joint = [a for a in actuators if a.kind != "site"]
    index = {a.mj_id: k for k, a in enumerate(joint)}
    out = []
    for s in specs:
        if s.type == "actuatorfrc":
            k = index.get(s.actuator)
            if k is None:
                notes.append(
                    f"sensor {s.name!r} (actuatorfrc): its actuator was not loaded as a joint "
                    "actuator (see the actuator notes); its value in sensordata is NaN"
                )
                s = SensorSpec(type="unsupported", body=-1, name=s.name, dim=1, source=s.type)
            else:
                gear = float(model.actuator_gear[s.actuator, 0])
                s = replace(s, actuator=k, gain=joint[k].gear / gear)
        out.append(s)
    return out
