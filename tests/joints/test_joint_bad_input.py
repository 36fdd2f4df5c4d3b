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


def test_bad_actuators_and_physics_name_the_joint():
    scene, a, b = _two_links()
    ball = scene.add_joint("ball", a, b, anchor=(0, 0, -1), name="wrist")
    with pytest.raises(ValueError, match="joint 'wrist'.*revolute and prismatic"):
        scene.add_actuator(ball, "position", kp=1.0)
    scene2, a2, b2 = _two_links()
    hinge = scene2.add_joint("revolute", a2, b2, anchor=(0, 0, -1), axis=(0, 1, 0), name="knee")
    for kwargs, message in [
        (dict(kind="servo"), "unknown actuator kind"),
        (dict(kind="position", kp=-1.0), "kp must be finite and >= 0"),
        (dict(gear=0.0), "gear must be finite and non-zero"),
        (dict(ctrl_range=(1.0, -1.0)), "ctrl_range must have lower <= upper"),
        (dict(force_range=(2.0, 1.0)), "force_range must have lower <= upper"),
        (dict(bias=float("nan")), "bias must be finite"),
        (dict(bias="push"), "bias must be a number"),
    ]:
        with pytest.raises(ValueError, match=f"joint 'knee'.*{message}"):
            scene2.add_actuator(hinge, **kwargs)
    with pytest.raises(ValueError, match="no joint named"):
        scene2.add_actuator("hip")


def test_limits_must_contain_the_loaded_configuration():
    scene, a, b = _two_links()
    scene.add_joint(
        "revolute", a, b, anchor=(0, 0, -1), axis=(0, 1, 0), limits=(0.2, 0.5), name="stop"
    )
    with pytest.raises(ValueError, match="joint 'stop'.*strictly inside the limits"):
        abdsim.World(scene)


def test_set_joint_forces_checks_its_input():
    scene, a, b = _two_links()
    scene.add_joint("ball", None, a, anchor=(0, 0, 0), name="top")
    scene.add_joint("revolute", a, b, anchor=(0, 0, -1), axis=(0, 1, 0), name="elbow")
    world = abdsim.World(scene)
    with pytest.raises(ValueError, match=r"expected 4 values"):
        world.set_joint_forces([1.0])
    with pytest.raises(ValueError, match="joint 'top' \\(ball\\) takes none"):
        world.set_joint_forces([1.0, 0.0, 0.0, 1.0])
    world.set_joint_forces([0.0, 0.0, 0.0, 1.0])  # fine: the hinge takes it
