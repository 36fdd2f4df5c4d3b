"""Scene.add_joint(collide=False) (the default): joined bodies do not collide with each other,
every other pair keeps its contact (abdsim/sim/contact_rules.py)."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from abdsim.sim.contact_rules import contact_rules
from tests.joints.conftest import LINK, link, rot_y

OVERLAP = 0.02  # the child's top reaches 2 cm into the parent's bottom end


def place(sc: abdsim.SimplicialComplex, angle: float, top) -> abdsim.SimplicialComplex:
    T = np.eye(4)
    T[:3, :3] = rot_y(angle)
    T[:3, 3] = top
    sc.transforms = T[None]
    return sc


def two_links(contact: bool = True, collide: bool = False, third: bool = False):
    """A hinge from the world holds link A (1 m, tilted 0.4 rad); link B hangs from A's bottom
    end on a second hinge, its top 2 cm inside A (they overlap near the hinge). `third`: a
    free box also overlapping B's top."""
    scene = abdsim.Scene(dt=1e-3, integrator="bdf2", contact=contact)
    a = scene.add(place(link(), 0.4, (0.0, 0.0, 0.0)))
    end = rot_y(0.4) @ np.array([0.0, 0.0, -LINK[2]])
    top_b = end + np.array([0.0, 0.0, OVERLAP])
    b = scene.add(place(link(), 0.0, top_b))
    scene.add_joint("revolute", None, a, anchor=(0, 0, 0), axis=(0, 1, 0), name="shoulder")
    scene.add_joint("revolute", a, b, anchor=top_b, axis=(0, 1, 0), name="elbow", collide=collide)
    if third:
        box = abdsim.geometry.box((0.05, 0.05, 0.05))
        sc = abdsim.geometry.triangle_mesh(box.positions, box.triangles)
        abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8, mass_density=1e3)
        scene.add(place(sc, 0.0, top_b - np.array([0.0, 0.0, 0.03])))
    return scene


def test_overlapping_joined_links_build_and_swing_as_without_contact():
    scene = two_links()
    assert scene.contact_exclusions() == [(0, 1)]
    world = abdsim.World(scene)
    free = abdsim.World(two_links(contact=False))
    worst = 0.0
    for _ in range(300):
        d = world.step()
        free.step()
        worst = max(worst, d.joint_violation)
    assert d.contact_pairs["point_triangle"] + d.contact_pairs["edge_edge"] == 0
    assert worst <= 1e-6, worst
    assert np.abs(world.joint_positions()).max() > 0.05  # it really swung
    # No barrier acted between them: the same motion as the scene without contact.
    gap = np.abs(world.q - free.q).max()
    assert gap <= 1e-6, gap


def test_collide_true_keeps_their_contact():
    with pytest.raises(ValueError, match="intersect|closer"):
        abdsim.World(two_links(collide=True))


def test_exclusion_is_per_pair_not_per_element():
    """A third body of the same contact element overlapping the links still collides."""
    with pytest.raises(ValueError, match="intersect|closer|inside"):
        abdsim.World(two_links(third=True))


def test_rules_copy_each_bodys_element():
    scene = two_links(third=True)
    scene.contact_table.set(0, 0, friction=0.3)
    scene.contact_table.set(0, "ground", enabled=False)
    rules = contact_rules(scene)
    a, b, c = rules.elements  # bodies 0, 1 get ids of their own; the box keeps element 0
    assert c == 0 and len({a, b, c}) == 3
    g = rules.ground_id
    assert rules.enabled[a, b] == 0 and rules.enabled[b, a] == 0
    for e in (a, b):
        assert rules.enabled[e, c] == 1 and rules.mu[e, c] == 0.3 and rules.mu[e, e] == 0.3
        assert rules.enabled[e, g] == 0  # element 0's ground rule follows it
    assert rules.mu[c, c] == 0.3 and rules.enabled[c, g] == 0
