"""Bad joints: each a ValueError naming the joint (at add_joint, or when the World is built
for what needs the bodies' poses)."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from tests.joints.conftest import chain_scene, link


def _two_links():
    scene = abdsim.Scene(dt=1e-3, contact=False)
    a, b = link(), link()
    T = np.eye(4)
    T[:3, 3] = (0, 0, -1)
    b.transforms = T[None]
    return scene, scene.add(a), scene.add(b)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(kind="screw"), "unknown joint kind"),
        (dict(axis=(0, 0, 0)), "axis is zero"),
        (dict(parent="a-b"), "same body"),
        (dict(damping=-0.1), "damping must be finite and >= 0"),
        (dict(armature=-1.0), "armature must be finite and >= 0"),
        (dict(stiffness=float("nan")), "stiffness"),
        (dict(limits=(0.5, -0.5)), "lower <= upper"),
        (dict(kind="ball", limits=(-1, 1)), "limits apply to revolute and prismatic"),
        (dict(kind="free"), "free joint must have the world"),
        (dict(anchor=(0, np.inf, 0)), "anchor must be finite"),
    ],
)
def test_bad_joint_raises_naming_it(kwargs, message):
    scene, a, b = _two_links()
    args = dict(kind="revolute", parent=a, child=b, anchor=(0, 0, -1), axis=(0, 1, 0))
    args.update(kwargs)
    if args["parent"] == "a-b":
        args["parent"] = b
    with pytest.raises(ValueError, match=message) as info:
        scene.add_joint(name="elbow", **args)
    assert "joint 'elbow'" in str(info.value)
    assert scene.joints == []


def test_second_parent_and_loop_are_rejected():
    scene, handles = chain_scene([0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="joint 'extra'.*already the child"):
        scene.add_joint("revolute", handles[0], handles[2], anchor=(0, 0, -1), name="extra")
    # a loop back to the root: the root's parent is the world, so tie the root under its own
    # descendant through a fresh chain head
    scene2 = abdsim.Scene(contact=False)
    x, y = scene2.add(link()), scene2.add(link())
    scene2.add_joint("ball", x, y, anchor=(0, 0, -1), name="down")
    with pytest.raises(ValueError, match="joint 'up'.*closes a kinematic loop"):
        scene2.add_joint("ball", y, x, anchor=(0, 0, -1), name="up")


def test_anchor_far_from_both_bodies_is_reported_by_the_world():
    scene, a, b = _two_links()
    scene.add_joint("ball", a, b, anchor=(10.0, 0.0, 0.0), name="far")
    with pytest.raises(ValueError, match="joint 'far': anchor .* is far from both bodies"):
        abdsim.World(scene)


def test_multi_instance_handle_and_bad_body_index():
    scene = abdsim.Scene(contact=False)
    sc = link()
    sc.instances.resize(2)
    h = scene.add(sc)
    with pytest.raises(ValueError, match="joint 'j'.*2 instances is ambiguous"):
        scene.add_joint("ball", None, h, name="j")
    with pytest.raises(ValueError, match="joint 'j'.*out of range"):
        scene.add_joint("ball", None, 5, name="j")
    with pytest.raises(ValueError, match="joint 'j'.*not the world"):
        scene.add_joint("ball", h.body(0), None, name="j")


def test_joint_physics_not_simulated_yet_is_refused():
    scene, a, b = _two_links()
    scene.add_joint("revolute", a, b, anchor=(0, 0, -1), axis=(0, 1, 0), damping=0.1, name="d")
    with pytest.raises(NotImplementedError, match="joint 'd'"):
        abdsim.World(scene)
