"""The NS/joints channel: each step's joint coordinates of a World with joints."""

from __future__ import annotations

import json

import numpy as np
from mcap.reader import make_reader

import abdsim
from tests.joints.conftest import chain_scene


def test_joint_states_are_logged_each_step(tmp_path):
    scene, _ = chain_scene([0.5, -0.3])
    world = abdsim.World(scene)
    path = tmp_path / "pendulum.mcap"
    expected = []
    for _ in range(5):
        world.step(log=path)
        expected.append(world.joint_positions())
    abdsim.bridges.close_logs(world)
    with open(path, "rb") as f:
        messages = [
            json.loads(m.data)
            for _, ch, m in make_reader(f).iter_messages()
            if ch.topic == "/abdsim/joints"
        ]
    assert len(messages) == 5
    for msg, q in zip(messages, expected, strict=True):
        assert [j["name"] for j in msg["joints"]] == ["j0", "j1"]
        assert [j["kind"] for j in msg["joints"]] == ["revolute", "revolute"]
        np.testing.assert_allclose([j["position"][0] for j in msg["joints"]], q, atol=1e-12)
        assert all(len(j["velocity"]) == 1 for j in msg["joints"])
