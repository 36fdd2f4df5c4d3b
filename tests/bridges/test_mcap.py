"""MCAP logging: exact round trip, Foxglove schemas, namespaces, truncated and killed runs."""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest
from mcap.reader import make_reader
from scipy.spatial.transform import Rotation

from abdsim.bridges import McapLogger, load_mjcf, log_info, read_log
from abdsim.bridges.log_reader import LogReadError


def synthetic_run(n_bodies=4, n_steps=30, seed=0):
    """Affine (slightly non-rigid) transforms and velocities with a rigid part we know."""
    rng = np.random.default_rng(seed)
    R = Rotation.random(n_bodies * n_steps, random_state=seed).as_matrix()
    T = np.tile(np.eye(4), (n_steps, n_bodies, 1, 1))
    T[:, :, :3, :3] = R.reshape(n_steps, n_bodies, 3, 3) @ (
        np.eye(3) + 1e-4 * rng.normal(size=(n_steps, n_bodies, 3, 3))
    )
    T[:, :, :3, 3] = rng.normal(size=(n_steps, n_bodies, 3))
    omega = rng.normal(size=(n_steps, n_bodies, 3))
    V = np.zeros_like(T)
    for k in range(n_steps):
        for i in range(n_bodies):
            V[k, i, :3, :3] = np.cross(omega[k, i], T[k, i, :3, :3].T).T  # [ω]× A
    V[:, :, :3, 3] = rng.normal(size=(n_steps, n_bodies, 3))
    return T, V, omega


def write_run(path, T, V, names=None, **options):
    names = names or [f"b{i}" for i in range(T.shape[1])]
    with McapLogger(path, names=names, **options) as log:
        for k in range(len(T)):
            log.log_state(0.01 * k, T[k], V[k])
            log.log_diagnostics(
                0.01 * k,
                {"newton_iterations": k % 4, "energies": [("kinetic", 0.5 * k), ("total", 1.0)]},
            )
    return names


def test_logged_states_read_back_exactly(tmp_path):
    T, V, omega = synthetic_run()
    names = write_run(tmp_path / "run.mcap", T, V)
    log = read_log(tmp_path / "run.mcap")
    assert log.names == names and not log.truncated
    np.testing.assert_array_equal(log.transforms, T)  # bit for bit
    np.testing.assert_array_equal(log.velocities, V)
    np.testing.assert_array_equal(log.times, 0.01 * np.arange(len(T)))
    np.testing.assert_array_equal(log.steps, np.arange(len(T)))
    np.testing.assert_array_equal(log.positions, T[:, :, :3, 3])
    np.testing.assert_array_equal(log.linear_velocities, V[:, :, :3, 3])
    # Orientation: the quaternion of the polar rotation of A (scipy as the reference).
    U, _, Wt = np.linalg.svd(T[:, :, :3, :3])
    ref = Rotation.from_matrix((U @ Wt).reshape(-1, 3, 3)).as_quat().reshape(log.quaternions.shape)
    ref *= np.sign(ref[..., 3:4])
    np.testing.assert_allclose(log.quaternions, ref, atol=1e-12)
    # Angular velocity: ω of Ȧ = [ω]× A (A is not exactly a rotation, Ȧ A⁻¹ still is [ω]×).
    np.testing.assert_allclose(log.angular_velocities, omega, atol=1e-12)
    np.testing.assert_array_equal(log.field("b2", "position"), T[:, 2, :3, 3])
    assert log.diagnostics["newton_iterations"].tolist() == [k % 4 for k in range(len(T))]
    np.testing.assert_array_equal(log.diagnostics["energies.kinetic"], 0.5 * np.arange(len(T)))


def test_foxglove_channels_and_scene_meshes(tmp_path, scenes_dir):
    res = load_mjcf(scenes_dir / "free_bodies.xml")
    with McapLogger(tmp_path / "scene.mcap", res, chunk_size=4096) as log:
        for k in range(5):
            log.log_state(0.01 * k, res.transforms())
    with open(tmp_path / "scene.mcap", "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        header = reader.get_header()
        topics = {
            ch.topic: (summary.schemas[ch.schema_id], ch.message_encoding)
            for ch in summary.channels.values()
        }
        counts = {
            summary.channels[c].topic: n
            for c, n in summary.statistics.channel_message_counts.items()
        }
        chunk_compression = {c.compression for c in summary.chunk_indexes}
    assert header.library.startswith("abdsim ")
    assert topics["/abdsim/tf"][0].name == "foxglove.FrameTransforms"
    assert topics["/abdsim/scene"][0].name == "foxglove.SceneUpdate"
    for topic in ("/abdsim/tf", "/abdsim/scene"):
        schema, encoding = topics[topic]
        assert (schema.encoding, encoding) == ("protobuf", "protobuf") and len(schema.data) > 100
    assert topics["/abdsim/bodies"][0].name == "abdsim.BodyStates"
    assert topics["/abdsim/bodies"][1] == "json"
    assert counts == {"/abdsim/scene": 1, "/abdsim/tf": 5, "/abdsim/bodies": 5}
    assert chunk_compression == {"zstd"} and len(summary.chunk_indexes) > 1
    info = log_info(tmp_path / "scene.mcap")
    assert info["bodies"] == {"/abdsim": res.names}
    assert (info["start_ns"], info["end_ns"]) == (0, 40_000_000)
    assert info["metadata"]["abdsim/abdsim"]["namespace"] == "/abdsim"


def test_two_namespaces_in_one_file(tmp_path):
    T, V, _ = synthetic_run(n_bodies=3, n_steps=10)
    T2 = T.copy()
    T2[:, :, :3, 3] += 1.0
    with McapLogger(tmp_path / "both.mcap", names=["a", "b", "c"], compression="lz4") as log:
        log.add_bodies(["a", "b", "c"], namespace="/mujoco")
        for k in range(10):
            log.log_state(0.01 * k, T[k], V[k])
            log.log_state(0.01 * k, T2[k], namespace="/mujoco")
    abd, mj = read_log(tmp_path / "both.mcap"), read_log(tmp_path / "both.mcap", "/mujoco")
    assert abd.namespace == "/abdsim" and mj.namespace == "/mujoco"
    np.testing.assert_array_equal(abd.transforms, T)
    np.testing.assert_array_equal(mj.transforms, T2)
    assert not mj.velocities.any()
    assert log_info(tmp_path / "both.mcap")["compression"] == ["lz4"]
    with pytest.raises(LogReadError, match="namespaces"):
        read_log(tmp_path / "both.mcap", "/nothing")


@pytest.mark.parametrize("compression", ["zstd", None])
def test_truncated_file_reads_up_to_its_last_complete_chunk(tmp_path, compression):
    T, V, _ = synthetic_run(n_bodies=5, n_steps=200)
    write_run(tmp_path / "full.mcap", T, V, chunk_size=8192, compression=compression)
    data = (tmp_path / "full.mcap").read_bytes()
    recovered = []
    for fraction in (0.3, 0.55, 0.8, 0.97):
        cut = tmp_path / f"cut{fraction}.mcap"
        cut.write_bytes(data[: int(len(data) * fraction)])
        with pytest.warns(UserWarning, match="truncated"):
            log = read_log(cut)
        assert log.truncated
        k = len(log.times)
        assert 0 < k < len(T)
        np.testing.assert_array_equal(log.transforms, T[:k])
        np.testing.assert_array_equal(log.velocities, V[:k])
        assert log_info(cut)["truncated"]
        recovered.append(k)
    assert recovered == sorted(recovered) and recovered[-1] > 0.8 * len(T)
    (tmp_path / "stub.mcap").write_bytes(data[:20])
    with pytest.raises(LogReadError):
        read_log(tmp_path / "stub.mcap")


def test_a_killed_run_leaves_a_readable_log(tmp_path):
    script = textwrap.dedent(
        f"""
        import sys, time
        import numpy as np
        from abdsim.bridges import McapLogger
        log = McapLogger({str(tmp_path / "killed.mcap")!r}, names=["a", "b"], chunk_size=4096)
        T = np.tile(np.eye(4), (2, 1, 1))
        for k in range(100000):
            T[:, 0, 3] = k
            log.log_state(0.001 * k, T)
            if k == 2000:
                print("ready", flush=True)
                time.sleep(60)
        """
    )
    proc = subprocess.Popen([sys.executable, "-P", "-c", script], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "ready"
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        log = read_log(tmp_path / "killed.mcap")
    assert log.truncated and 100 < len(log.times) <= 2001
    np.testing.assert_array_equal(log.positions[:, 0, 0], np.arange(len(log.times)))


def test_logger_rejects_bad_input(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        McapLogger(tmp_path / "missing" / "x.mcap")
    (tmp_path / "exists.mcap").write_bytes(b"")
    with pytest.raises(FileExistsError):
        McapLogger(tmp_path / "exists.mcap", overwrite=False)
    with pytest.raises(ValueError, match="compression"):
        McapLogger(tmp_path / "c.mcap", compression="gzip")
    with McapLogger(tmp_path / "bad.mcap", names=["a", "b"]) as log:
        with pytest.raises(ValueError, match="2 bodies"):
            log.log_state(0.0, np.tile(np.eye(4), (3, 1, 1)))
        with pytest.raises(ValueError, match="shape"):
            log.log_state(0.0, np.zeros((2, 3, 3)))
        bad = np.tile(np.eye(4), (2, 1, 1))
        bad[0, 0, 0] = np.nan
        with pytest.raises(ValueError, match="not finite"):
            log.log_state(0.0, bad)
        with pytest.raises(ValueError, match="time"):
            log.log_state(-1.0, np.tile(np.eye(4), (2, 1, 1)))
        with pytest.raises(ValueError, match="already registered"):
            log.add_bodies(["x"])
    with pytest.raises(ValueError, match="closed"):
        log.log_state(0.0, np.tile(np.eye(4), (2, 1, 1)))


def test_reader_rejects_what_is_not_an_abdsim_log(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_log(tmp_path / "nothing.mcap")
    (tmp_path / "text.mcap").write_text("hello, this is not an MCAP file at all")
    with pytest.raises(LogReadError, match="not an MCAP file"):
        read_log(tmp_path / "text.mcap")
    with McapLogger(tmp_path / "empty.mcap"):
        pass
    with pytest.raises(LogReadError, match="no abdsim body states"):
        read_log(tmp_path / "empty.mcap")
