"""The Foxglove channels decode with the protobuf schemas embedded in the log (as Foxglove
itself decodes them), and carry the World's poses and the body meshes."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from abdsim.bridges import McapLogger

pytest.importorskip("mcap_protobuf")


def decoded(path, topic):
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory

    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        return [(s.name, m) for s, _, _, m in reader.iter_decoded_messages(topics=[topic])]


def test_frame_transforms_and_scene_decode(tmp_path):
    sc = abdsim.geometry.box((0.2, 0.1, 0.05))
    sc.instances.resize(2)
    t = np.array(sc.transforms)
    t[1, :3, 3] = [1.0, 0.0, 0.5]
    sc.transforms = t
    abdsim.AffineBodyConstitution().apply_to(sc, 1e8)
    sc.instances["velocity"][0][:3, 3] = [1.0, 0.0, 2.0]
    sc.instances["velocity"][1][:3, :3] = [[0, -3, 0], [3, 0, 0], [0, 0, 0]]  # spin about z
    scene = abdsim.Scene(dt=0.01)
    scene.add(sc)
    world = abdsim.World(scene)
    poses = []
    path = tmp_path / "run.mcap"
    with McapLogger(path, world) as log:
        for _ in range(5):
            world.step()
            log.log_world(world)
            poses.append(world.transforms())

    tf = decoded(path, "/abdsim/tf")
    assert len(tf) == 5 and {name for name, _ in tf} == {"foxglove.FrameTransforms"}
    for (_, msg), T in zip(tf, poses, strict=True):
        assert [x.parent_frame_id for x in msg.transforms] == ["world", "world"]
        for x, Tb in zip(msg.transforms, T, strict=True):
            np.testing.assert_allclose(
                [x.translation.x, x.translation.y, x.translation.z], Tb[:3, 3], atol=1e-12
            )
            q = np.array([x.rotation.x, x.rotation.y, x.rotation.z, x.rotation.w])
            assert abs(np.linalg.norm(q) - 1) < 1e-9
            # rotation of the quaternion ≈ A (A is a rotation up to O(1/κ))
            x_, y_, z_, w_ = q
            R = np.array(
                [
                    [1 - 2 * (y_**2 + z_**2), 2 * (x_ * y_ - z_ * w_), 2 * (x_ * z_ + y_ * w_)],
                    [2 * (x_ * y_ + z_ * w_), 1 - 2 * (x_**2 + z_**2), 2 * (y_ * z_ - x_ * w_)],
                    [2 * (x_ * z_ - y_ * w_), 2 * (y_ * z_ + x_ * w_), 1 - 2 * (x_**2 + y_**2)],
                ]
            )
            np.testing.assert_allclose(R, Tb[:3, :3], atol=1e-5)

    scene_msgs = decoded(path, "/abdsim/scene")
    assert scene_msgs and scene_msgs[0][0] == "foxglove.SceneUpdate"
    entities = scene_msgs[0][1].entities
    assert len(entities) == 2
    for e in entities:
        assert e.frame_id.startswith("abdsim/")
        (tri,) = e.triangles  # one indexed triangle list per body
        assert len(tri.points) == len(sc.positions)
        np.testing.assert_array_equal(np.reshape(tri.indices, (-1, 3)), sc.triangles)
        np.testing.assert_allclose([[p.x, p.y, p.z] for p in tri.points], sc.positions)
