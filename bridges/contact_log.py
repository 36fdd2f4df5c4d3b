"""Contact forces in MCAP logs: a JSON channel to plot and arrows in Foxglove's 3D panel.

Per namespace ``NS`` of a :class:`~abdsim.bridges.McapLogger`, a World with contact adds:

=======================  ========================  ========  =================================
topic                    schema                    encoding  content
=======================  ========================  ========  =================================
``NS/contacts``          ``abdsim.ContactForces``  json      per step: every contact pair
                                                             (bodies, point, normal, normal
                                                             and friction force) and every
                                                             body's contact wrench
``NS/contact_arrows``    ``foxglove.SceneUpdate``  protobuf  per step: an arrow per pair for
                                                             the normal force and one for
                                                             friction, in the ``world`` frame
=======================  ========================  ========  =================================

Foxglove's Plot panel can plot e.g. ``/abdsim/contacts.wrenches[:]{name=="box"}.force[2]``.
``McapLogger.log_world`` calls :func:`log_world_contacts` (so ``world.step(log=...)`` logs
them); the forces are ``World.contacts()`` and ``World.contact_wrenches()`` of the last step.
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: Schema of ``NS/contacts``.
CONTACTS_SCHEMA: dict[str, Any] = {
    "title": "abdsim.ContactForces",
    "description": "Contact forces of one time step: per contact pair and per body",
    "type": "object",
    "properties": {
        "timestamp": {
            "type": "object",
            "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}},
        },
        "step": {"type": "integer", "description": "steps taken"},
        "time": {"type": "number", "description": "simulated time (s)"},
        "total_normal_force": {"type": "number", "description": "sum over pairs (N)"},
        "contacts": {
            "type": "array",
            "items": {
                "type": "object",
                "properties": {
                    "bodies": {
                        "type": "array",
                        "items": {"type": "string"},
                        "description": 'first and second body ("ground" for the ground)',
                    },
                    "body_ids": {"type": "array", "items": {"type": "integer"}},
                    "point": {"type": "array", "items": {"type": "number"}},
                    "normal": {
                        "type": "array",
                        "items": {"type": "number"},
                        "description": "unit, from the second body towards the first",
                    },
                    "normal_force": {"type": "number", "description": "on the first body (N)"},
                    "friction_force": {
                        "type": "array",
                        "items": {"type": "number"},
                        "description": "on the first body (N)",
                    },
                },
            },
        },
        "wrenches": {
            "type": "array",
            "items": {
                "type": "object",
                "properties": {
                    "name": {"type": "string"},
                    "force": {"type": "array", "items": {"type": "number"}},
                    "torque": {
                        "type": "array",
                        "items": {"type": "number"},
                        "description": "about the centre of mass (N m)",
                    },
                },
            },
        },
    },
}

#: Arrow length per newton (m/N) and shaft diameter (m) in ``NS/contact_arrows``.
ARROW_SCALE = 0.01
ARROW_DIAMETER = 0.004
_NORMAL_COLOR = (0.20, 0.70, 0.30)
_FRICTION_COLOR = (0.95, 0.45, 0.10)


def arrow_orientations(directions: np.ndarray) -> np.ndarray:
    """Quaternions [x, y, z, w] turning +x onto each unit direction (k, 3) -> (k, 4).

    The shortest-arc rotation: q ∝ (x̂ × d, 1 + x̂ · d); d = −x̂ turns about z.
    """
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    q = np.zeros((len(d), 4))
    q[:, 1] = -d[:, 2]  # x̂ × d = (0, −d_z, d_y)
    q[:, 2] = d[:, 1]
    q[:, 3] = 1.0 + d[:, 0]
    opposite = q[:, 3] < 1e-12
    q[opposite] = [0.0, 0.0, 1.0, 0.0]
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def contacts_message(names: list[str], contacts: Any, wrenches: np.ndarray) -> dict[str, Any]:
    """The JSON body of an ``NS/contacts`` message (without timestamp, step and time)."""
    label = np.array([*names, "ground"], dtype=object)  # index -1 is the ground
    ids = np.asarray(contacts.bodies)
    pairs = [
        {
            "bodies": [label[a], label[b]],
            "body_ids": [a, b],
            "point": p,
            "normal": n,
            "normal_force": fn,
            "friction_force": ft,
        }
        for (a, b), p, n, fn, ft in zip(
            ids.tolist(),
            contacts.points.tolist(),
            contacts.normals.tolist(),
            contacts.normal_force.tolist(),
            contacts.friction_force.tolist(),
            strict=True,
        )
    ]
    W = np.asarray(wrenches).tolist()
    return {
        "total_normal_force": float(np.sum(contacts.normal_force)),
        "contacts": pairs,
        "wrenches": [
            {"name": name, "force": w[:3], "torque": w[3:]}
            for name, w in zip(names, W, strict=True)
        ],
    }


def arrows_update(fox: Any, contacts: Any, time_ns: int, scale: float = ARROW_SCALE) -> Any:
    """A ``foxglove.SceneUpdate`` replacing the entity ``contact_forces`` with one arrow per
    non-zero normal force and per non-zero friction force, ``scale`` m/N long, from the
    contact point along the force on the pair's first body."""
    fm = fox.messages
    normal = contacts.normal_force[:, None] * contacts.normals
    vectors = np.concatenate([normal, contacts.friction_force])
    starts = np.concatenate([contacts.points, contacts.points])
    colors = [_NORMAL_COLOR] * len(normal) + [_FRICTION_COLOR] * len(normal)
    length = np.linalg.norm(vectors, axis=1)
    keep = length > 0
    quats = arrow_orientations(vectors[keep] / length[keep, None])
    arrows = []
    for p, q, n, (r, g, b) in zip(
        starts[keep].tolist(),
        quats.tolist(),
        length[keep].tolist(),
        [c for c, k in zip(colors, keep, strict=True) if k],
        strict=True,
    ):
        shaft = scale * n
        arrows.append(
            fm.ArrowPrimitive(
                pose=fm.Pose(
                    position=fm.Vector3(x=p[0], y=p[1], z=p[2]),
                    orientation=fm.Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]),
                ),
                shaft_length=shaft,
                shaft_diameter=ARROW_DIAMETER,
                head_length=min(3 * ARROW_DIAMETER, shaft),
                head_diameter=2 * ARROW_DIAMETER,
                color=fm.Color(r=r, g=g, b=b, a=1.0),
            )
        )
    ts = fm.Timestamp(sec=time_ns // 1_000_000_000, nsec=time_ns % 1_000_000_000)
    entity = fm.SceneEntity(timestamp=ts, frame_id="world", id="contact_forces", arrows=arrows)
    return fm.SceneUpdate(entities=[entity])


def log_world_contacts(
    logger: Any, world: Any, time: float, *, step: int | None = None, namespace: str | None = None
) -> bool:
    """Log ``world``'s contact forces of its last step to ``NS/contacts`` and
    ``NS/contact_arrows``; returns False (logging nothing) for a World without contact."""
    from abdsim.bridges.mcap_log import _dumps

    if getattr(world, "contact", None) is None or not callable(getattr(world, "contacts", None)):
        return False
    contacts = world.contacts()
    wrenches = world.contact_wrenches()
    # Channels of the logger's namespace entry (registered on first use).
    entry = logger._namespace(namespace, world.num_bodies)
    if len(entry.names) != len(wrenches):
        raise ValueError(
            f"{entry.name}: {len(entry.names)} bodies registered, the World has {len(wrenches)}"
        )
    t_ns = logger._time_ns(time)
    msg = contacts_message(entry.names, contacts, wrenches)
    msg["timestamp"] = {"sec": t_ns // 1_000_000_000, "nsec": t_ns % 1_000_000_000}
    msg["step"] = int(world.step_count if step is None else step)
    msg["time"] = float(time)
    logger._write(entry, "contacts", _dumps(msg), t_ns, CONTACTS_SCHEMA)
    arrows = arrows_update(logger._fox, contacts, t_ns)
    logger._write(entry, "contact_arrows", arrows.encode(), t_ns)
    return True
