"""Which loaded bodies may touch, and with which friction: the source's contact rules.

The loaders give every body its own contact element (its body index) and fill
``Scene.contact_table`` from a :class:`ContactRules`:

* **MJCF** (MuJoCo's collision filter, geom by geom, then per body pair): two geoms collide
  when ``contype``/``conaffinity`` are compatible (``ct1 & ca2 or ct2 & ca1``), they are not
  on a parent–child pair of weld groups (MuJoCo's ``filterparent``; the world body is exempt,
  and the filter is off under ``<flag filterparent="disable"/>``) and their bodies are not
  listed in ``<contact><exclude>``. ``<contact><pair>`` geoms always collide, with the pair's
  friction. A body pair collides when any of its geom pairs does; its friction is the largest
  pair friction, each pair's being MuJoCo's default ``max(μ1, μ2)`` (or the explicit pair's).
  The same rules against the ground's plane geoms give the ground's row.
* **URDF**: links joined by a joint never collide (each body with its parent body), nor the
  pairs an SRDF lists as ``<disable_collisions link1= link2=/>``, nor (MoveIt's "default"
  rule) a moving body and another link of the robot whose surfaces already touch or lie within
  ``TOUCH_MARGIN`` of each other in the loaded configuration: real collision meshes overlap at
  the joints (a trunk and its thighs), which an intersection-free simulator cannot start from.
  A note lists those pairs.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


@dataclass
class ContactRules:
    """Pairwise contact rules of a loaded scene (body indices; ``i < j`` in every key).

    Attributes:
        excluded: body pairs that never collide.
        friction: μ of body pairs that differ from the scene's default.
        ground_excluded: bodies that never touch the ground.
        ground_friction: μ of a body against the ground.
    """

    excluded: set[tuple[int, int]] = field(default_factory=set)
    friction: dict[tuple[int, int], float] = field(default_factory=dict)
    ground_excluded: set[int] = field(default_factory=set)
    ground_friction: dict[int, float] = field(default_factory=dict)

    def apply(self, scene, n_bodies: int) -> None:
        """Write the rules into ``scene.contact_table`` (body ``i`` is contact element ``i``)."""
        table = scene.contact_table
        for i, j in sorted(self.excluded):
            table.set(i, j, enabled=False)
        for (i, j), mu in sorted(self.friction.items()):
            if (i, j) not in self.excluded:
                table.set(i, j, enabled=True, friction=mu)
        for i in sorted(self.ground_excluded):
            table.set(i, "ground", enabled=False)
        for i, mu in sorted(self.ground_friction.items()):
            if i not in self.ground_excluded:
                table.set(i, "ground", enabled=True, friction=mu)


def _pair(i: int, j: int) -> tuple[int, int]:
    return (i, j) if i < j else (j, i)


# -- URDF -------------------------------------------------------------------------------------
def urdf_rules(bodies, srdf: Path | None = None) -> ContactRules:
    """Adjacent bodies (joined by a joint) and SRDF ``disable_collisions`` pairs excluded."""
    rules = ContactRules()
    for i, body in enumerate(bodies):
        if body.parent is not None:
            rules.excluded.add(_pair(i, body.parent))
    if srdf is not None:
        link_body = {link: i for i, b in enumerate(bodies) for link in b.links}
        for a, b in srdf_disabled_pairs(srdf):
            if a in link_body and b in link_body and link_body[a] != link_body[b]:
                rules.excluded.add(_pair(link_body[a], link_body[b]))
    return rules


def srdf_disabled_pairs(srdf: Path) -> list[tuple[str, str]]:
    """The ``(link1, link2)`` of every ``<disable_collisions>`` of an SRDF file.

    Raises:
        ValueError: malformed XML, or an element without both link names (named).
    """
    try:
        root = ET.parse(srdf).getroot()
    except ET.ParseError as e:
        raise ValueError(f"malformed SRDF {srdf}: {e}") from e
    pairs = []
    for k, elem in enumerate(root.iter("disable_collisions")):
        a, b = elem.get("link1"), elem.get("link2")
        if not a or not b:
            raise ValueError(f"SRDF {srdf.name}: <disable_collisions> #{k} needs link1 and link2")
        pairs.append((a, b))
    return pairs


# -- MJCF -------------------------------------------------------------------------------------
def mjcf_rules(mujoco, model, bodies, geom_ids: dict[str, int], ground_geoms: list[int]):
    """MuJoCo's collision filter and friction, per pair of loaded bodies (module docstring)."""
    m = model
    body_of = np.full(m.ngeom, -1, dtype=np.int64)
    for i, b in enumerate(bodies):
        for name in b.geoms:
            body_of[geom_ids[name]] = i
    for g in ground_geoms:
        body_of[g] = len(bodies)  # the ground, one pseudo-body after the last
    geoms = np.flatnonzero(body_of >= 0)
    ok = _mjcf_geom_filter(mujoco, m, geoms)
    mu = np.asarray(m.geom_friction[geoms, 0], dtype=np.float64)
    friction = np.maximum(mu[:, None], mu[None, :])
    index = {int(g): k for k, g in enumerate(geoms)}
    for p in range(m.npair):
        a, b = index.get(int(m.pair_geom1[p])), index.get(int(m.pair_geom2[p]))
        if a is not None and b is not None:
            ok[a, b] = ok[b, a] = True
            friction[a, b] = friction[b, a] = float(m.pair_friction[p, 0])
    owner = body_of[geoms]
    n = len(bodies) + 1
    collide = np.zeros((n, n), dtype=bool)
    best = np.full((n, n), -np.inf)
    rows, cols = np.nonzero(ok & (owner[:, None] != owner[None, :]))
    collide[owner[rows], owner[cols]] = True
    np.maximum.at(best, (owner[rows], owner[cols]), friction[rows, cols])
    fixed = np.array([b.kind == "fixed" for b in bodies] + [True])
    rules = ContactRules()
    ground = n - 1
    for i in range(n - 1):
        for j in range(i + 1, n):
            if fixed[i] and fixed[j]:
                continue
            if j == ground:
                if not ground_geoms:
                    continue
                if not collide[i, j]:
                    rules.ground_excluded.add(i)
                else:
                    rules.ground_friction[i] = float(best[i, j])
            elif not collide[i, j]:
                rules.excluded.add((i, j))
            else:
                rules.friction[(i, j)] = float(best[i, j])
    return rules


def _mjcf_geom_filter(mujoco, m, geoms: np.ndarray) -> np.ndarray:
    """(k, k) bool: which of ``geoms`` pass MuJoCo's contype/parent/exclude filter."""
    ct = np.asarray(m.geom_contype[geoms], dtype=np.int64)
    ca = np.asarray(m.geom_conaffinity[geoms], dtype=np.int64)
    ok = ((ct[:, None] & ca[None, :]) != 0) | ((ct[None, :] & ca[:, None]) != 0)
    body = np.asarray(m.geom_bodyid[geoms], dtype=np.int64)
    weld = np.asarray(m.body_weldid, dtype=np.int64)[body]
    weld_parent = np.asarray(m.body_weldid, dtype=np.int64)[
        np.asarray(m.body_parentid, dtype=np.int64)[weld]
    ]
    filterparent = not (m.opt.disableflags & int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT))
    if filterparent:
        related = (weld[:, None] == weld_parent[None, :]) | (weld_parent[:, None] == weld[None, :])
        nonworld = (weld[:, None] != 0) & (weld[None, :] != 0)
        ok &= ~(related & nonworld)
    ok &= weld[:, None] != weld[None, :]
    if m.nexclude:
        # exclude_signature = (body1 << 16) + body2, in the order the file gives them.
        sig = {
            (min(s >> 16, s & 0xFFFF) << 16) + max(s >> 16, s & 0xFFFF)
            for s in map(int, m.exclude_signature)
        }
        key = (np.minimum(body[:, None], body[None, :]) << 16) + np.maximum(
            body[:, None], body[None, :]
        )
        excluded = np.isin(key, list(sig))
        ok &= ~excluded
    return ok


#: Surfaces of one robot closer than this (m) when loaded never collide (URDF; twice the
#: default barrier distance d̂, so that no barrier starts active between them).
TOUCH_MARGIN = 2e-3


def exclude_touching(bodies, rules: ContactRules, notes: list[str]) -> None:
    """Add the pairs (one body dynamic) that touch at load to ``rules.excluded``, with a note."""
    import coal

    moving = [i for i, b in enumerate(bodies) if b.kind == "dynamic"]
    if not moving:
        return
    models: dict[int, object] = {}

    def model(i: int):
        if i not in models:
            g = bodies[i].geometry
            T = np.asarray(g.transforms[0])
            V = np.asarray(g.positions) @ T[:3, :3].T + T[:3, 3]
            m = coal.BVHModelOBBRSS()
            m.beginModel(len(g.triangles), len(V))
            m.addVertices(np.ascontiguousarray(V, dtype=np.float64))
            m.addTriangles(np.ascontiguousarray(g.triangles, dtype=np.int64))
            m.endModel()
            models[i] = m
        return models[i]

    found = []
    for i in moving:
        for j in range(len(bodies)):
            pair = _pair(i, j)
            if j == i or pair in rules.excluded or (j in moving and j < i):
                continue
            request = coal.CollisionRequest()
            request.security_margin = TOUCH_MARGIN
            result = coal.CollisionResult()
            if coal.collide(
                model(i), coal.Transform3s(), model(j), coal.Transform3s(), request, result
            ):
                rules.excluded.add(pair)
                found.append((bodies[pair[0]].name, bodies[pair[1]].name))
    # A link wholly inside another's solid (talos: a sensor box inside the torso) crosses no
    # surface, so only containment finds it (abdsim.geometry.containment).
    from abdsim.geometry.containment import nested_pairs

    V = []
    for b in bodies:
        T = np.asarray(b.geometry.transforms[0])
        V.append(np.asarray(b.geometry.positions) @ T[:3, :3].T + T[:3, 3])
    boxes = np.array([[v.min(axis=0), v.max(axis=0)] for v in V])
    solids = {i: (V[i], np.asarray(b.geometry.triangles)) for i, b in enumerate(bodies)}
    moving_set = set(moving)

    def may_collide(a: int, b: int) -> bool:
        return (a in moving_set or b in moving_set) and _pair(a, b) not in rules.excluded

    for inner, outer in nested_pairs(boxes, solids, np.array([v[0] for v in V]), may_collide):
        rules.excluded.add(_pair(inner, outer))
        found.append((bodies[inner].name, bodies[outer].name))
    if found:
        notes.append(
            f"{len(found)} pair(s) of links touch (closer than {TOUCH_MARGIN:g} m) or nest in "
            f"the loaded configuration and never collide: {found}"
        )


def exclude_touching_ground(bodies, grounds, rules: ContactRules, notes: list[str]) -> None:
    """Dynamic bodies that reach within ``TOUCH_MARGIN`` of a ground plane at load (a reacher
    lying on its table) never touch the ground, with a note: IPC cannot start in contact."""
    found = []
    for i, b in enumerate(bodies):
        if b.kind != "dynamic" or i in rules.ground_excluded:
            continue
        g = b.geometry
        T = np.asarray(g.transforms[0])
        V = np.asarray(g.positions) @ T[:3, :3].T + T[:3, 3]
        for ground in grounds:
            if float((V @ np.asarray(ground.normal)).min()) - ground.height < TOUCH_MARGIN:
                rules.ground_excluded.add(i)
                found.append(b.name)
                break
    if found:
        notes.append(
            f"{len(found)} body(ies) touch the ground (closer than {TOUCH_MARGIN:g} m) in the "
            f"loaded configuration and never collide with it: {found}"
        )
