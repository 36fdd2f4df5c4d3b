"""Logs are complete MCAP files whenever control returns; corrupted chunks are caught.

The reference reader is the stock ``mcap`` library's seeking reader, which needs the summary
section and the chunk indexes; ``read_log`` must never return a number a flipped bit changed.
"""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest
from mcap.reader import make_reader

from abdsim.bridges import McapLogger, close_logs, load_mjcf, read_log
from abdsim.bridges.log_reader import LogReadError


def stock_read(path):
    """Summary statistics and the per-topic message counts the stock reader sees."""
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        topics = {c.id: c.topic for c in summary.channels.values()}
        counts: dict[str, int] = {}
        for _, channel, _ in reader.iter_messages():  # walks the chunk indexes
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
    stats = {topics[c]: n for c, n in summary.statistics.channel_message_counts.items()}
    return summary, stats, counts


def test_log_is_complete_after_each_step_call(tmp_path, scenes_dir):
    world = load_mjcf(scenes_dir / "free_bodies.xml").make_world()
    path = tmp_path / "run.mcap"
    world.step(20, log=path)
    summary, stats, counts = stock_read(path)
    # The initial state and 20 steps; one diagnostics message per step; the meshes once.
    assert counts["/abdsim/bodies"] == counts["/abdsim/tf"] == 21
    assert counts["/abdsim/diagnostics"] == 20 and counts["/abdsim/scene"] == 1
    assert stats == counts
    assert summary.statistics.message_end_time == round(20 * world.scene.dt * 1e9)
    first = read_log(path)
    assert not first.truncated and len(first.times) == 21
    np.testing.assert_array_equal(first.transforms[-1], world.transforms())

    world.step(10, log=str(path))  # the same file continues
    summary, stats, counts = stock_read(path)
    assert counts["/abdsim/bodies"] == 31 and counts["/abdsim/diagnostics"] == 30
    assert stats == counts and summary.statistics.chunk_count == len(summary.chunk_indexes)
    data = read_log(path)
    assert not data.truncated and not data.corrupted
    np.testing.assert_array_equal(data.steps, np.arange(31))
    np.testing.assert_array_equal(data.transforms[:21], first.transforms)
    np.testing.assert_array_equal(data.transforms[-1], world.transforms())
    close_logs(world)
    assert stock_read(path)[2] == counts  # closing writes the same complete file


def test_many_short_calls_still_make_full_chunks(tmp_path, scenes_dir):
    world = load_mjcf(scenes_dir / "free_bodies.xml").make_world()
    path = tmp_path / "loop.mcap"
    for k in range(30):
        world.step(1, log=path)
        summary, stats, counts = stock_read(path)  # complete after every call
        assert counts["/abdsim/bodies"] == k + 2 and stats == counts
    # The chunk left open at each return is rewritten, not cut: one chunk per 256 kB, not
    # one per call.
    assert summary.statistics.chunk_count == len(summary.chunk_indexes) <= 3
    data = read_log(path)
    np.testing.assert_array_equal(data.steps, np.arange(31))
    np.testing.assert_array_equal(data.transforms[-1], world.transforms())


def write_log(path, n_steps=120, n_bodies=3, compression="zstd"):
    rng = np.random.default_rng(7)
    T = np.tile(np.eye(4), (n_steps, n_bodies, 1, 1))
    T[:, :, :3, 3] = rng.normal(size=(n_steps, n_bodies, 3))
    names = [f"b{i}" for i in range(n_bodies)]
    with McapLogger(path, names=names, chunk_size=2048, compression=compression) as log:
        for k in range(n_steps):
            log.log_state(0.01 * k, T[k])
    return T


def chunk_spans(path):
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    return [(c.chunk_start_offset, c.chunk_length) for c in summary.chunk_indexes]


def test_a_bit_flipped_chunk_is_reported_and_nothing_after_it_is_returned(tmp_path):
    path = tmp_path / "clean.mcap"
    T = write_log(path, compression=None)  # uncompressed: the flip leaves valid JSON behind
    data = path.read_bytes()
    spans = chunk_spans(path)
    assert len(spans) > 5
    # Flip the lowest bit of a digit in a position of chunk 4: a different but valid number.
    start, length = spans[3]
    at = data.index(b'"position":[', start) + len(b'"position":[')
    at += next(i for i, c in enumerate(data[at : at + 30]) if chr(c) in "123456789")
    assert at < start + length
    flipped = bytearray(data)
    flipped[at] ^= 0x01
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(flipped))
    with pytest.warns(UserWarning, match="chunk 4 is corrupted"):
        log = read_log(bad)
    assert log.truncated and log.corrupted
    k = len(log.times)
    assert 0 < k < len(T)
    np.testing.assert_array_equal(log.positions, T[:k, :, :3, 3])
    # Exactly the states of chunks 1-3 came back: the clean file's prefix up to chunk 4.
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    t_end = summary.chunk_indexes[2].message_end_time
    assert log.times[-1] == pytest.approx(t_end * 1e-9)


def test_no_single_bit_flip_inside_chunks_changes_a_number(tmp_path):
    path = tmp_path / "clean.mcap"
    T = write_log(path, n_steps=60)
    data = path.read_bytes()
    positions = [s + i for s, n in chunk_spans(path) for i in range(9, n)]  # after the opcode+len
    rng = np.random.default_rng(0)
    caught = 0
    for trial, pos in enumerate(rng.choice(positions, size=60, replace=False)):
        flipped = bytearray(data)
        flipped[pos] ^= 1 << int(rng.integers(8))
        bad = tmp_path / f"bad{trial}.mcap"
        bad.write_bytes(bytes(flipped))
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            try:
                log = read_log(bad)
            except LogReadError:
                caught += 1
                continue
        k = len(log.times)
        np.testing.assert_array_equal(log.positions, T[:k, :, :3, 3])  # never a changed number
        if k < len(T):
            assert log.truncated and seen, f"flip at byte {pos} lost data silently"
            caught += 1
    assert caught > 40  # almost every flip inside a chunk is in its payload


def test_log_info_into_a_closed_pipe_exits_quietly(tmp_path):
    path = tmp_path / "run.mcap"
    write_log(path, n_steps=5)
    proc = subprocess.Popen(
        [sys.executable, "-P", "-m", "abdsim", "log", "info", "--json", str(path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.close()  # like `| head` that has gone before the first line is written
    _, err = proc.communicate(timeout=120)
    assert err.decode().strip() == "" and proc.returncode == 0
