"""Contact forces in MCAP logs (abdsim.bridges.contact_log): the JSON channel carries exactly
``World.contacts()`` / ``World.contact_wrenches()``, the arrows decode (protobuf, as Foxglove
decodes them) with the forces' lengths and directions."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from mcap.reader import make_reader
from scipy.spatial.transform import Rotation

import abdsim
from abdsim.bridges import McapLogger, log_info
from abdsim.bridges.contact_log import ARROW_SCALE, arrow_orientations


def resting_box_world(contact=True):
    """A 1 kg box 0.5 mm above the ground, sliding at 0.3 m/s (μ = 0.5: it stops in 0.06 s)."""
    sc = abdsim.geometry.from_trimesh(trimesh.creation.box(extents=(0.1, 0.1, 0.1)))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8, mass_density=1e3)
    T = np.eye(4)
    T[2, 3] = 0.0505
    sc.transforms = T[None]
    sc.instances["velocity"][0][0, 3] = 0.3
    scene = abdsim.Scene(dt=0.01, contact=contact)
    scene.add_ground(0.0)
    scene.add(sc)
    return abdsim.World(scene)


def json_messages(path, topic):
    with open(path, "rb") as f:
        return [json.loads(m.data) for _, _, m in make_reader(f).iter_messages(topics=[topic])]


def test_arrow_orientations_turn_x_onto_the_direction():
    """Against scipy: the quaternion rotates +x onto d (including d = ±x)."""
    rng = np.random.default_rng(3)
    d = rng.normal(size=(50, 3))
    d = np.concatenate([d, [[1, 0, 0], [-1, 0, 0], [0, 0, -1]]])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    q = arrow_orientations(d)
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(Rotation.from_quat(q).apply([1.0, 0.0, 0.0]), d, atol=1e-12)


def test_world_log_carries_the_contact_forces(tmp_path):
    """world.step(n, log=...) logs one contacts message per step; the last equals the
    World's arrays; the wrench of the box is logged by name."""
    world = resting_box_world()
    path = tmp_path / "contacts.mcap"
    world.step(20, log=path)
    abdsim.bridges.close_logs(world)
    msgs = json_messages(path, "/abdsim/contacts")
    assert len(msgs) == 20 and [m["step"] for m in msgs] == list(range(1, 21))
    last = msgs[-1]
    c = world.contacts()
    assert len(last["contacts"]) == len(c) == 4
    got = {k: np.array([p[k] for p in last["contacts"]]) for k in last["contacts"][0]}
    np.testing.assert_array_equal(got["body_ids"], c.bodies)
    (name,) = log_info(path)["bodies"]["/abdsim"]
    assert {tuple(b) for b in got["bodies"]} == {(name, "ground")}
    np.testing.assert_array_equal(got["point"], c.points)
    np.testing.assert_array_equal(got["normal"], c.normals)
    np.testing.assert_array_equal(got["normal_force"], c.normal_force)
    np.testing.assert_array_equal(got["friction_force"], c.friction_force)
    assert last["total_normal_force"] == pytest.approx(c.normal_force.sum(), rel=1e-15)
    (w,) = last["wrenches"]
    assert w["name"] == name
    np.testing.assert_array_equal(w["force"] + w["torque"], world.contact_wrenches()[0])
    # while it slides (it stops within 0.1 s) the logged friction opposes the motion: along
    # −x, tangent to the ground (z exactly 0), and across the slide (y) at round-off only.
    # The triangulated box is mirror-symmetric in y only to round-off (its y-odd dofs hold
    # ~1e-19 after the first step, ~1e-16 once the exact shape Hessian carries them), so
    # the four contacts' y-forces cancel to round-off of the friction force, not to 0.0.
    friction = np.sum([p["friction_force"] for p in msgs[2]["contacts"]], axis=0)
    assert friction[0] < -1.0 and friction[2] == 0.0
    assert abs(friction[1]) < 1e-12 * abs(friction[0])


def test_contact_arrows_decode_with_the_forces(tmp_path):
    """Each non-zero normal and friction force is an arrow at the contact point, ARROW_SCALE
    m/N long, pointing along the force (quaternion applied to +x)."""
    pytest.importorskip("mcap_protobuf")
    from mcap_protobuf.decoder import DecoderFactory

    world = resting_box_world()
    path = tmp_path / "arrows.mcap"
    with McapLogger(path, world) as log:
        for _ in range(10):
            world.step()
            log.log_world(world)
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        msgs = [m for _, _, _, m in reader.iter_decoded_messages(topics=["/abdsim/contact_arrows"])]
    assert len(msgs) == 10
    (entity,) = msgs[-1].entities
    assert entity.frame_id == "world" and entity.id == "contact_forces"
    c = world.contacts()
    forces = np.concatenate([c.normal_force[:, None] * c.normals, c.friction_force])
    points = np.concatenate([c.points, c.points])
    nonzero = np.linalg.norm(forces, axis=1) > 0
    assert len(entity.arrows) == nonzero.sum() == 8
    for a, f, p in zip(entity.arrows, forces[nonzero], points[nonzero], strict=True):
        pos = [a.pose.position.x, a.pose.position.y, a.pose.position.z]
        o = a.pose.orientation
        direction = Rotation.from_quat([o.x, o.y, o.z, o.w]).apply([1.0, 0.0, 0.0])
        np.testing.assert_allclose(pos, p, atol=1e-15)
        assert a.shaft_length == pytest.approx(ARROW_SCALE * np.linalg.norm(f), rel=1e-12)
        np.testing.assert_allclose(direction, f / np.linalg.norm(f), atol=1e-9)


def test_world_without_contact_logs_no_contact_channels(tmp_path):
    world = resting_box_world(contact=False)
    path = tmp_path / "free.mcap"
    world.step(3, log=path)
    abdsim.bridges.close_logs(world)
    with open(path, "rb") as f:
        topics = {ch.topic for ch in make_reader(f).get_summary().channels.values()}
    assert "/abdsim/bodies" in topics and not topics & {
        "/abdsim/contacts",
        "/abdsim/contact_arrows",
    }
