"""Joints and contact in one coupled solve: a two-link arm, hinged about the vertical and
driven by a position actuator, sweeps into a box resting on the ground and pushes it. No
intersection at any step (checked independently with coal) and no joint violation."""

from __future__ import annotations

import numpy as np

import abdsim
from tests.contact.conftest import WorldContact


def test_two_link_arm_pushes_a_box_without_intersection():
    scene = abdsim.Scene(dt=0.01)
    scene.add_ground(0.0)
    links = []
    for k in range(2):
        sc = WorldContact.box((0.44, 0.06, 0.06), kappa=1e9)
        WorldContact.place(sc, [[0.25 + 0.5 * k, 0.0, 0.1]])
        links.append(scene.add(sc, contact_element=1))
    box = WorldContact.box((0.2, 0.2, 0.2), kappa=1e9, density=200.0)
    WorldContact.place(box, [[0.75, -0.25, 0.102]])
    h_box = scene.add(box, contact_element=2)
    shoulder = scene.add_joint("revolute", None, links[0], anchor=(0, 0, 0.1), axis=(0, 0, 1))
    scene.add_joint(
        "revolute", links[0], links[1], anchor=(0.5, 0, 0.1), axis=(0, 0, 1), damping=0.5
    )
    scene.add_actuator(shoulder, "position", kp=200.0, kv=20.0)
    world = abdsim.World(scene)
    world.ctrl[:] = -0.6  # swing towards −y, through where the box stands
    start = world.q[h_box.start][:3].copy()
    worst_gap, worst_violation, hits = np.inf, 0.0, 0
    for step in range(100):
        d = world.step()
        worst_violation = max(worst_violation, d.joint_violation, d.joint_violation_angle)
        if step % 5 == 4:
            n, gap, low = WorldContact.coal_check(world)
            hits += n
            worst_gap = min(worst_gap, gap, low)
    moved = np.linalg.norm(world.q[h_box.start][:2] - start[:2])
    assert hits == 0 and worst_gap > 0.0, (hits, worst_gap)
    assert worst_violation <= 1e-6, worst_violation
    assert moved > 0.02, moved  # the arm pushed the box
    assert world.joint_positions()[0] < -0.1  # and kept turning towards its target
