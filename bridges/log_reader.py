"""Read abdsim MCAP logs back into numpy arrays (also logs cut short by a killed run).

The reader streams the file record by record (``mcap.stream_reader.StreamReader``), so it
needs no summary section: a file truncated mid-way yields every message of its complete
chunks and ``LogData.truncated`` is set (with a warning). Every chunk's CRC is checked: a
corrupted chunk (a flipped bit on disk) is treated like the end of a truncated file: the
messages before it are returned, ``LogData.truncated`` and ``LogData.corrupted`` are set and
a warning names the chunk, so no corrupted number is ever returned as data.
"""

from __future__ import annotations

import json
import os
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

BODY_SCHEMA = "abdsim.BodyStates"
DIAGNOSTICS_SCHEMA = "abdsim.StepDiagnostics"

#: Per-body fields of :class:`LogData` that ``field()`` / the CLI can plot, and their size.
BODY_FIELDS = {
    "position": 3,
    "orientation": 4,
    "linear_velocity": 3,
    "angular_velocity": 3,
    "transform": 12,
    "velocity": 12,
}


class LogReadError(ValueError):
    """A file that is not an MCAP log, or holds no abdsim body states."""


@dataclass
class _Scan:
    channels: dict[int, tuple[str, str, str]]  # id -> (topic, schema name, encoding)
    messages: list[tuple[int, int, bytes]]  # (channel id, log time, data) of kept channels
    counts: dict[int, int]  # messages per channel id (all channels)
    time_range: tuple[int | None, int | None]
    metadata: dict[str, dict[str, str]]
    truncated: bool
    error: str | None
    chunks: int
    corrupted: bool
    compression: set[str]


def _scan(path: Path, first_only: bool = False) -> _Scan:
    """Stream the file; keep the data of abdsim's JSON channels (only their first message
    with ``first_only``), count every channel's messages."""
    from mcap.exceptions import InvalidMagic
    from mcap.records import Channel, Chunk, Message, Metadata, Schema
    from mcap.stream_reader import StreamReader, breakup_chunk

    if not path.exists():
        raise FileNotFoundError(f"log file not found: {path}")
    if not path.is_file():
        raise LogReadError(f"log path is not a file: {path}")
    schemas: dict[int, str] = {}
    channels: dict[int, tuple[str, str, str]] = {}
    messages: list[tuple[int, int, bytes]] = []
    counts: dict[int, int] = {}
    times: list[int | None] = [None, None]
    metadata: dict[str, dict[str, str]] = {}
    truncated, error, chunks, compression = False, None, 0, set()
    corrupted = False
    kept = (BODY_SCHEMA, DIAGNOSTICS_SCHEMA)

    def handle(rec: Any) -> None:
        if isinstance(rec, Schema):
            schemas[rec.id] = rec.name
        elif isinstance(rec, Channel):
            channels[rec.id] = (rec.topic, schemas.get(rec.schema_id, ""), rec.message_encoding)
        elif isinstance(rec, Message):
            c, t = rec.channel_id, rec.log_time
            counts[c] = counts.get(c, 0) + 1
            times[0] = t if times[0] is None else min(times[0], t)
            times[1] = t if times[1] is None else max(times[1], t)
            if channels.get(c, ("", ""))[1] in kept and not (first_only and counts[c] > 1):
                messages.append((c, t, rec.data))
        elif isinstance(rec, Metadata):
            metadata[rec.name] = dict(rec.metadata)

    with open(path, "rb") as f:
        reader = StreamReader(f, emit_chunks=True)
        try:
            for rec in reader.records:
                if isinstance(rec, Chunk):
                    try:
                        # Decode the whole chunk before using any of it: a chunk whose CRC
                        # (or decompression) fails contributes nothing.
                        inner_records = breakup_chunk(rec, validate_crc=True)
                    except Exception as e:
                        truncated, corrupted = True, True
                        error = f"chunk {chunks + 1} is corrupted ({type(e).__name__}: {e})"
                        break
                    chunks += 1
                    compression.add(rec.compression or "none")
                    for inner in inner_records:
                        handle(inner)
                else:
                    handle(rec)
        except InvalidMagic as e:
            if not channels and not messages:
                raise LogReadError(f"{path} is not an MCAP file: {e}") from e
            truncated, error = True, f"{type(e).__name__}: {e}"
        except Exception as e:  # any decoding failure past the last complete record
            if chunks == 0 and not channels:
                raise LogReadError(f"{path}: no complete MCAP record could be read ({e})") from e
            truncated, error = True, f"{type(e).__name__}: {e}"
    return _Scan(
        channels=channels,
        messages=messages,
        counts=counts,
        time_range=tuple(times),
        metadata=metadata,
        truncated=truncated,
        error=error,
        chunks=chunks,
        corrupted=corrupted,
        compression=compression,
    )


@dataclass
class LogData:
    """Body states and diagnostics of one namespace of an abdsim log.

    Attributes:
        path: the log file.
        namespace: the namespace read (``/abdsim``).
        names: body names (index = body index).
        steps: (T,) time-step indices; ``times``: (T,) simulated times (s).
        transforms, velocities: (T, n, 4, 4) exact poses ``[[A, p], [0, 1]]`` and dT/dt.
        positions: (T, n, 3); quaternions: (T, n, 4) ``[x, y, z, w]`` of the rotation
            nearest to A; linear_velocities, angular_velocities: (T, n, 3), world frame.
        diagnostics: numeric diagnostics fields as arrays over the diagnostics messages
            (``time`` and ``step`` included; nested dicts flattened as ``energies.kinetic``;
            missing values are NaN).
        truncated: the file ended inside a record (a killed run), or a corrupted chunk
            stopped the reading; what came before was read.
        corrupted: a chunk failed its CRC check (or did not decompress); the data stop
            before it.
    """

    path: Path
    namespace: str
    names: list[str]
    steps: np.ndarray
    times: np.ndarray
    transforms: np.ndarray
    velocities: np.ndarray
    positions: np.ndarray
    quaternions: np.ndarray
    linear_velocities: np.ndarray
    angular_velocities: np.ndarray
    diagnostics: dict[str, np.ndarray] = field(default_factory=dict)
    truncated: bool = False
    corrupted: bool = False

    def index(self, name: str) -> int:
        """Body index of ``name``."""
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"no body named {name!r} in the log; bodies: {self.names}") from None

    def field(self, name: str, what: str) -> np.ndarray:
        """One body's field over time: (T, k) for ``what`` in :data:`BODY_FIELDS`."""
        i = self.index(name)
        arrays = {
            "position": self.positions,
            "orientation": self.quaternions,
            "linear_velocity": self.linear_velocities,
            "angular_velocity": self.angular_velocities,
            "transform": self.transforms[:, :, :3, :].reshape(len(self.times), -1, 12),
            "velocity": self.velocities[:, :, :3, :].reshape(len(self.times), -1, 12),
        }
        if what not in arrays:
            raise KeyError(f"unknown body field {what!r}; choose one of {list(BODY_FIELDS)}")
        return arrays[what][:, i]

    def __repr__(self) -> str:
        span = f"{self.times[0]:g}..{self.times[-1]:g} s" if len(self.times) else "empty"
        return (
            f"<LogData {self.path.name} {self.namespace}: {len(self.names)} bodies, "
            f"{len(self.times)} states ({span}){' TRUNCATED' if self.truncated else ''}"
            f"{' CORRUPTED' if self.corrupted else ''}>"
        )


def _namespaces(scan: _Scan) -> list[str]:
    return sorted({t[: -len("/bodies")] for t, s, _ in scan.channels.values() if s == BODY_SCHEMA})


def _pick_namespace(scan: _Scan, namespace: str | None, path: Path) -> str:
    found = _namespaces(scan)
    if namespace is not None:
        ns = "/" + namespace.strip("/")
        if ns not in found:
            raise LogReadError(f"{path} has no body states under {ns!r}; namespaces: {found}")
        return ns
    if not found:
        raise LogReadError(f"{path} holds no abdsim body states ({BODY_SCHEMA} channels)")
    return "/abdsim" if "/abdsim" in found else found[0]


def read_log(path: str | os.PathLike, namespace: str | None = None) -> LogData:
    """Read the body states and diagnostics of one namespace of an abdsim MCAP log.

    Args:
        path: the ``.mcap`` file.
        namespace: e.g. ``/abdsim`` (the default when present) or ``/mujoco``.

    Raises:
        FileNotFoundError: no such file.
        LogReadError (a ValueError): not an MCAP file, or no body states under the namespace.
    """
    p = Path(path).expanduser()
    scan = _scan(p)
    ns = _pick_namespace(scan, namespace, p)
    if scan.corrupted:
        warnings.warn(
            f"{p}: {scan.error}; read the {scan.chunks} chunks before it, nothing after",
            stacklevel=2,
        )
    elif scan.truncated:
        warnings.warn(
            f"{p} is truncated ({scan.error}); read every complete chunk before the cut",
            stacklevel=2,
        )
    body_ids = {c for c, (t, s, _) in scan.channels.items() if t == f"{ns}/bodies"}
    diag_ids = {c for c, (t, s, _) in scan.channels.items() if t == f"{ns}/diagnostics"}
    states = [json.loads(d) for c, _, d in scan.messages if c in body_ids]
    diags = [json.loads(d) for c, _, d in scan.messages if c in diag_ids]
    states.sort(key=lambda m: (m["time"], m.get("step", 0)))
    names = [b["name"] for b in states[0]["bodies"]] if states else []
    for m in states:
        if [b["name"] for b in m["bodies"]] != names:
            raise LogReadError(f"{p}: the bodies under {ns} change between steps")
    n, T = len(names), len(states)

    def stack(key: str, k: int) -> np.ndarray:
        out = np.array([[b[key] for b in m["bodies"]] for m in states], dtype=np.float64)
        return out.reshape(T, n, k)

    transforms = np.tile(np.eye(4), (T, n, 1, 1))
    velocities = np.zeros((T, n, 4, 4))
    if T and n:
        transforms[:, :, :3, :] = stack("transform", 12).reshape(T, n, 3, 4)
        velocities[:, :, :3, :] = stack("velocity", 12).reshape(T, n, 3, 4)
    return LogData(
        path=p,
        namespace=ns,
        names=names,
        steps=np.array([m.get("step", i) for i, m in enumerate(states)], dtype=np.int64),
        times=np.array([m["time"] for m in states], dtype=np.float64),
        transforms=transforms,
        velocities=velocities,
        positions=stack("position", 3) if T and n else np.zeros((T, n, 3)),
        quaternions=stack("orientation", 4) if T and n else np.zeros((T, n, 4)),
        linear_velocities=stack("linear_velocity", 3) if T and n else np.zeros((T, n, 3)),
        angular_velocities=stack("angular_velocity", 3) if T and n else np.zeros((T, n, 3)),
        diagnostics=_diagnostics_arrays(diags),
        truncated=scan.truncated,
        corrupted=scan.corrupted,
    )


def _flatten(msg: dict[str, Any], prefix: str = "") -> Iterator[tuple[str, Any]]:
    for k, v in msg.items():
        if k == "timestamp":
            continue
        key = f"{prefix}{k}"
        if isinstance(v, dict):
            yield from _flatten(v, key + ".")
        elif isinstance(v, bool) or isinstance(v, (int, float)) or v is None:
            yield key, v


def _diagnostics_arrays(diags: list[dict[str, Any]]) -> dict[str, np.ndarray]:
    diags = sorted(diags, key=lambda m: (m.get("time", 0.0), m.get("step", 0)))
    rows = [dict(_flatten(m)) for m in diags]
    keys = sorted({k for r in rows for k in r})
    out = {}
    for k in keys:
        values = [r.get(k) for r in rows]
        out[k] = np.array([np.nan if v is None else float(v) for v in values], dtype=np.float64)
    return out


def log_info(path: str | os.PathLike) -> dict[str, Any]:
    """Summary of an MCAP log: channels, schemas, message counts, time range, bodies.

    Works on truncated files too (``truncated`` is then True).
    """
    p = Path(path).expanduser()
    scan = _scan(p, first_only=True)
    counts = scan.counts
    t_min, t_max = scan.time_range
    bodies: dict[str, list[str]] = {}
    for ns in _namespaces(scan):
        ids = {c for c, (t, _, _) in scan.channels.items() if t == f"{ns}/bodies"}
        first = next((d for c, _, d in scan.messages if c in ids), None)
        if first is not None:
            bodies[ns] = [b["name"] for b in json.loads(first)["bodies"]]
        elif f"abdsim{ns}" in scan.metadata:
            bodies[ns] = json.loads(scan.metadata[f"abdsim{ns}"].get("bodies", "[]"))
    return {
        "path": str(p),
        "size_bytes": p.stat().st_size,
        "channels": [
            {"id": c, "topic": t, "schema": s, "encoding": e, "messages": counts.get(c, 0)}
            for c, (t, s, e) in sorted(scan.channels.items())
        ],
        "messages": sum(counts.values()),
        "start_ns": t_min,
        "end_ns": t_max,
        "chunks": scan.chunks,
        "compression": sorted(scan.compression),
        "bodies": bodies,
        "metadata": scan.metadata,
        "truncated": scan.truncated,
        "corrupted": scan.corrupted,
        "error": scan.error,
    }
