"""Which bodies collide, with which friction and damping: the scene's contact table, ground
and joint exclusions resolved into per-body contact element ids and square rule matrices over
them (what the C++ ``ContactSettings`` takes).

Joined bodies that must not collide (``Scene.add_joint(..., collide=False)``) are a pair of
*bodies*, not of elements: each body of such a pair gets an element id of its own that copies
every rule of its original element, and only the pair itself is switched off.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from abdsim.sim.scene import Scene


@dataclass
class ContactRules:
    """Per-body element ids, the ground's id and, when any rule departs from the defaults,
    the (n, n) matrices enabled / μ / ζ / restitution e (−1: none) over ids 0..ground_id
    (None otherwise)."""

    elements: np.ndarray
    ground_id: int
    enabled: np.ndarray | None = None
    mu: np.ndarray | None = None
    zeta: np.ndarray | None = None
    restitution: np.ndarray | None = None


def contact_rules(scene: Scene) -> ContactRules:
    """The scene's contact rules (see the module docstring)."""
    from abdsim.sim.scene import GROUND

    st = scene.settings
    elements = scene.contact_elements().astype(np.int64)
    ids = set(elements.tolist())
    for (a, b), _ in scene.contact_table.items():
        ids.update(e for e in (a, b) if e != GROUND)
    first_own = max(ids, default=-1) + 1  # the ground's id without exclusions
    exclusions = scene.contact_exclusions()
    origin = list(range(first_own))  # the element whose rules each id follows
    for k, body in enumerate(sorted({b for pair in exclusions for b in pair})):
        origin.append(int(elements[body]))
        elements[body] = first_own + k
    ground_id = len(origin)
    ground = scene.ground
    ground_mu = None if ground is None else ground.friction
    ground_zeta = None if ground is None else ground.damping
    if not (len(scene.contact_table) or ground_mu is not None or ground_zeta is not None):
        if not exclusions:
            return ContactRules(elements, ground_id)

    # The rules over the original ids (the ground last), then copied to every id.
    n = first_own + 1
    enabled = np.ones((n, n), dtype=np.int32)
    mu = np.full((n, n), float(st.friction))
    zeta = np.full((n, n), float(st.contact_damping))
    e = np.full((n, n), -1.0 if st.restitution is None else float(st.restitution))
    if ground_mu is not None:
        mu[first_own, :] = mu[:, first_own] = ground_mu
    if ground_zeta is not None:
        zeta[first_own, :] = zeta[:, first_own] = ground_zeta
    for (a, b), (on, friction) in scene.contact_table.items():
        i = first_own if a == GROUND else a
        j = first_own if b == GROUND else b
        enabled[i, j] = enabled[j, i] = int(on)
        if friction is not None:
            mu[i, j] = mu[j, i] = friction
        damping = scene.contact_table.damping(a, b)
        if damping is not None:
            zeta[i, j] = zeta[j, i] = damping
        restitution = scene.contact_table.restitution(a, b)
        if restitution is not None:
            e[i, j] = e[j, i] = restitution
    index = np.array(origin + [first_own])
    grid = np.ix_(index, index)
    enabled, mu, zeta, e = enabled[grid], mu[grid], zeta[grid], e[grid]
    for a, b in exclusions:
        enabled[elements[a], elements[b]] = enabled[elements[b], elements[a]] = 0
    return ContactRules(elements, ground_id, enabled, mu, zeta, e)
