"""MCAP logs of abdsim runs that open (and animate) in Foxglove with no setup.

Per namespace ``NS`` (default ``/abdsim``; e.g. ``/mujoco`` for a reference run in the same
file) the log has four channels:

* ``NS/scene`` (``foxglove.SceneUpdate``, protobuf), once: every body's surface (triangle
  list, frame-locked);
* ``NS/tf`` (``foxglove.FrameTransforms``, protobuf), per step: ``world`` → each body frame
  ``ns/NAME``;
* ``NS/bodies`` (``abdsim.BodyStates``, json), per step: exact 3x4 transform and dT/dt,
  position, quaternion, twist per body;
* ``NS/diagnostics`` (``abdsim.StepDiagnostics``, json), per step: solver diagnostics;
* ``NS/joints`` (``abdsim.JointStates``, json), per step, for a World with joints: each
  joint's name, kind, position and velocity.

Foxglove's 3D panel shows the bodies from ``scene`` + ``tf``; its Plot panel can plot e.g.
``/abdsim/bodies.bodies[:]{name=="box"}.position[2]``. ``tf`` carries the rotation nearest to
each body's affine ``A`` (polar decomposition); ``bodies`` carries ``A`` itself, so
:func:`abdsim.bridges.read_log` returns exactly what was logged.

The file is chunked and compressed (zstd by default) by
:class:`~abdsim.bridges.mcap_writer.CheckpointWriter` (messages encoded by ``foxglove-sdk``).
Whenever control returns to the caller of ``world.step(n, log=path)`` / :func:`step_and_log`
the file is a complete MCAP file (summary and footer included) that any MCAP reader opens; a
later call continues it. Writes go straight to the operating system, so a run that is killed
mid-way leaves a file whose every complete chunk can still be read (``read_log`` does so,
warning that the file is truncated). Log times are simulated time in nanoseconds (plus
``time_offset_ns``).
"""

from __future__ import annotations

import atexit
import json
import math
import os
import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from abdsim.sim.pose import angular_velocities, nearest_rotations, quaternions_wxyz

#: Schema of ``NS/bodies``.
BODY_STATES_SCHEMA: dict[str, Any] = {
    "title": "abdsim.BodyStates",
    "description": "Pose and velocity of every affine body at one time step",
    "type": "object",
    "properties": {
        "timestamp": {
            "type": "object",
            "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}},
        },
        "step": {"type": "integer", "description": "time-step index"},
        "time": {"type": "number", "description": "simulated time (s)"},
        "bodies": {
            "type": "array",
            "items": {
                "type": "object",
                "properties": {
                    "name": {"type": "string"},
                    "frame_id": {"type": "string"},
                    "position": {"type": "array", "items": {"type": "number"}},
                    "orientation": {
                        "type": "array",
                        "items": {"type": "number"},
                        "description": "quaternion [x, y, z, w] of the rotation nearest to A",
                    },
                    "linear_velocity": {"type": "array", "items": {"type": "number"}},
                    "angular_velocity": {
                        "type": "array",
                        "items": {"type": "number"},
                        "description": "world-frame ω from Ȧ A⁻¹ (skew part)",
                    },
                    "transform": {
                        "type": "array",
                        "items": {"type": "number"},
                        "description": "rows 0-2 of the 4x4 transform [A p], row-major (12)",
                    },
                    "velocity": {
                        "type": "array",
                        "items": {"type": "number"},
                        "description": "rows 0-2 of dT/dt [Ȧ ṗ], row-major (12)",
                    },
                },
            },
        },
    },
}

#: Schema of ``NS/diagnostics`` (further solver fields are added as they appear).
DIAGNOSTICS_SCHEMA: dict[str, Any] = {
    "title": "abdsim.StepDiagnostics",
    "description": "What one time step of the solver did",
    "type": "object",
    "properties": {
        "timestamp": {
            "type": "object",
            "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}},
        },
        "step": {"type": "integer"},
        "time": {"type": "number"},
        "newton_iterations": {"type": "integer"},
        "converged": {"type": "boolean"},
        "residual": {"type": "number"},
        "energies": {"type": "object", "additionalProperties": {"type": "number"}},
        "min_distance": {"type": ["number", "null"]},
        "wall_time": {"type": "number", "description": "seconds spent in the step"},
    },
    "additionalProperties": True,
}

#: Schema of ``NS/joints`` (MuJoCo's joint conventions, see ``World.joint_positions``).
JOINT_STATES_SCHEMA: dict[str, Any] = {
    "title": "abdsim.JointStates",
    "description": 'Joint coordinates after a step (Plot: joints[:]{name=="j"}.position[0])',
    "type": "object",
    "properties": {
        "timestamp": DIAGNOSTICS_SCHEMA["properties"]["timestamp"],
        "step": {"type": "integer"},
        "joints": {
            "type": "array",
            "items": {
                "type": "object",
                "properties": {
                    "name": {"type": "string"},
                    "kind": {"type": "string"},
                    "position": {"type": "array", "items": {"type": "number"}},
                    "velocity": {"type": "array", "items": {"type": "number"}},
                },
            },
        },
    },
}

_PALETTE = (
    (0.26, 0.52, 0.96),
    (0.96, 0.58, 0.19),
    (0.30, 0.75, 0.42),
    (0.88, 0.30, 0.33),
    (0.58, 0.42, 0.80),
    (0.55, 0.55, 0.58),
)
_KIND_COLOR = {"fixed": (0.6, 0.6, 0.62), "kinematic": (0.96, 0.58, 0.19)}


@dataclass
class _Namespace:
    name: str
    names: list[str]
    frames: list[str]
    channels: dict[str, Any]


def _normalise_namespace(namespace: str) -> str:
    ns = "/" + namespace.strip().strip("/")
    if ns == "/" or any(c.isspace() for c in ns):
        raise ValueError(
            f"namespace must be a non-empty topic prefix like '/abdsim', got {namespace!r}"
        )
    return ns


def _unique_names(names: Sequence[str]) -> list[str]:
    seen: dict[str, int] = {}
    out = []
    for raw in names:
        name = str(raw) or "body"
        if name in seen:
            seen[name] += 1
            name = f"{name}#{seen[name]}"
        seen.setdefault(name, 0)
        out.append(name)
    return out


class McapLogger:
    """Write an abdsim run (poses, twists, diagnostics, meshes) to an MCAP file.

    Args:
        path: the ``.mcap`` file to write (replaced if ``overwrite``).
        source: what to log: an ``abdsim.World``, an ``abdsim.Scene``, a
            :class:`~abdsim.bridges.LoadResult`, or None (then call :meth:`add_bodies`). Its
            bodies (names and meshes) are registered under ``namespace`` right away.
        namespace: topic prefix of this source's channels (``/abdsim``).
        names: body names overriding the source's.
        compression: ``"zstd"`` (default), ``"lz4"`` or None.
        chunk_size: target uncompressed chunk size in bytes: also what a killed run can lose.
        time_offset_ns: added to every log time (simulated time in ns).
        overwrite: replace an existing file (else FileExistsError).
        metadata: key/value strings written as the MCAP metadata record ``abdsim``.

    Use as a context manager, or call :meth:`close`::

        with McapLogger("run.mcap", world) as log:
            for _ in range(100):
                world.step()
                log.log_world(world)
    """

    def __init__(
        self,
        path: str | os.PathLike,
        source: Any = None,
        *,
        namespace: str = "/abdsim",
        names: Sequence[str] | None = None,
        compression: str | None = "zstd",
        chunk_size: int = 256 * 1024,
        time_offset_ns: int = 0,
        overwrite: bool = True,
        metadata: dict[str, str] | None = None,
    ) -> None:
        import foxglove

        from abdsim.bridges.mcap_writer import CheckpointWriter

        if compression not in ("zstd", "lz4", None):
            raise ValueError(f"compression must be 'zstd', 'lz4' or None, got {compression!r}")
        if int(chunk_size) <= 0:
            raise ValueError(f"chunk_size must be positive, got {chunk_size}")
        self.path = Path(path).expanduser()
        if self.path.exists() and not overwrite:
            raise FileExistsError(f"{self.path} exists (pass overwrite=True to replace it)")
        if not self.path.parent.is_dir():
            raise FileNotFoundError(f"folder {self.path.parent} does not exist")
        self.default_namespace = _normalise_namespace(namespace)
        self.time_offset_ns = int(time_offset_ns)
        self._namespaces: dict[str, _Namespace] = {}
        self._steps: dict[str, int] = {}
        self._fox = foxglove
        self._schema_ids: dict[str, int] = {}
        # Unbuffered: every chunk the writer finishes is in the OS's hands at once.
        self._file = open(self.path, "wb", buffering=0)  # noqa: SIM115 - closed in close()
        try:
            self._writer = CheckpointWriter(
                self._file,
                compression=compression,
                chunk_size=int(chunk_size),
                library=f"abdsim {_abdsim_version()}",
            )
        except Exception:
            self._file.close()
            raise
        self._closed = False
        info = {"writer": "abdsim", "version": _abdsim_version()}
        info.update({str(k): str(v) for k, v in (metadata or {}).items()})
        self._writer.add_metadata("abdsim", info)
        if source is not None:
            from abdsim.bridges import _world_adapter as adapter

            bodies = adapter.describe_bodies(source)
            self.add_bodies(
                names if names is not None else [b.name for b in bodies],
                meshes=[(b.vertices, b.triangles) for b in bodies],
                kinds=[b.kind for b in bodies],
            )
        elif names is not None:
            self.add_bodies(names)

    # -- registration ---------------------------------------------------------------------------
    def add_bodies(
        self,
        names: Sequence[str],
        meshes: Sequence[tuple[np.ndarray, np.ndarray] | None] | None = None,
        *,
        namespace: str | None = None,
        kinds: Sequence[str] | None = None,
        time: float = 0.0,
    ) -> list[str]:
        """Register the bodies of a namespace and log their meshes once (``NS/scene``).

        Args:
            names: one name per body (made unique with ``#k`` suffixes).
            meshes: per body ``(vertices (n, 3) in the body frame, triangles (m, 3))`` or None.
            namespace: defaults to the logger's namespace.
            kinds: per body ``"fixed"``/``"kinematic"``/``"dynamic"`` (mesh colour).
            time: simulated time stamped on the scene message.

        Returns:
            The Foxglove frame ids of the bodies.
        """
        self._check_open()
        ns = _normalise_namespace(namespace or self.default_namespace)
        if ns in self._namespaces:
            raise ValueError(f"bodies of namespace {ns!r} are already registered")
        unique = _unique_names(names)
        prefix = ns.strip("/")
        frames = [f"{prefix}/{n}" for n in unique]
        entry = _Namespace(ns, unique, frames, {})
        self._namespaces[ns] = entry
        self._steps[ns] = 0
        self._writer.add_metadata(f"abdsim{ns}", {"namespace": ns, "bodies": json.dumps(unique)})
        if meshes is not None:
            if len(meshes) != len(unique):
                raise ValueError(f"got {len(meshes)} meshes for {len(unique)} bodies")
            self._log_scene(entry, meshes, kinds, time)
        return frames

    def _channel(self, entry: _Namespace, kind: str, json_schema: dict | None = None) -> int:
        """The MCAP channel id of ``NS/kind`` (registered with its schema on first use):
        Foxglove protobuf for ``tf`` and ``*scene``/``*arrows`` (SceneUpdate), else JSON with
        ``json_schema`` (default: body states or diagnostics by kind)."""
        ch = entry.channels.get(kind)
        if ch is not None:
            return ch
        fm = self._fox.messages
        if kind in ("tf", "scene") or kind.endswith("arrows"):
            proto = fm.FrameTransforms if kind == "tf" else fm.SceneUpdate
            schema = proto.get_schema()
            name, encoding, data = schema.name, schema.encoding, schema.data
            msg_encoding = "protobuf"
        else:
            if json_schema is None:
                json_schema = BODY_STATES_SCHEMA if kind == "bodies" else DIAGNOSTICS_SCHEMA
            name, encoding, msg_encoding = json_schema["title"], "jsonschema", "json"
            data = json.dumps(json_schema).encode("utf-8")
        if name not in self._schema_ids:
            self._schema_ids[name] = self._writer.add_schema(name, encoding, bytes(data))
        ch = self._writer.add_channel(f"{entry.name}/{kind}", msg_encoding, self._schema_ids[name])
        entry.channels[kind] = ch
        return ch

    def _write(
        self, entry: _Namespace, kind: str, data: bytes, t_ns: int, json_schema: dict | None = None
    ) -> None:
        self._writer.add_message(self._channel(entry, kind, json_schema), t_ns, data)

    def _namespace(self, namespace: str | None, n: int | None = None) -> _Namespace:
        ns = _normalise_namespace(namespace or self.default_namespace)
        entry = self._namespaces.get(ns)
        if entry is None:
            if n is None:
                raise ValueError(f"no bodies registered under {ns!r}: call add_bodies first")
            names = [f"body{i}" for i in range(n)]
            self.add_bodies(names, namespace=ns)
            entry = self._namespaces[ns]
        return entry

    # -- logging ---------------------------------------------------------------------------------
    def log_state(
        self,
        time: float,
        transforms: np.ndarray,
        velocities: np.ndarray | None = None,
        *,
        step: int | None = None,
        namespace: str | None = None,
    ) -> None:
        """Log every body's pose (``NS/tf``, ``NS/bodies``) at simulated ``time``.

        Args:
            time: simulated time (s).
            transforms: (n, 4, 4) body transforms ``[[A, p], [0, 1]]``.
            velocities: (n, 4, 4) dT/dt, zero when omitted.
            step: time-step index (counts calls per namespace by default).
            namespace: which registered namespace (unregistered ones get ``body{i}`` names).
        """
        self._check_open()
        T = np.asarray(transforms, dtype=np.float64)
        if T.ndim == 2:
            T = T[None]
        if T.ndim != 3 or T.shape[1:] != (4, 4):
            raise ValueError(f"transforms must have shape (n, 4, 4), got {np.shape(transforms)}")
        entry = self._namespace(namespace, len(T))
        n = len(entry.names)
        if len(T) != n:
            raise ValueError(f"{entry.name}: got {len(T)} transforms for {n} bodies")
        V = np.zeros_like(T) if velocities is None else np.asarray(velocities, dtype=np.float64)
        if V.shape != T.shape:
            raise ValueError(f"velocities must have shape {T.shape}, got {V.shape}")
        if not (np.isfinite(T).all() and np.isfinite(V).all()):
            raise ValueError(f"{entry.name}: transforms or velocities are not finite")
        if step is None:
            step = self._steps[entry.name]
        self._steps[entry.name] = int(step) + 1
        t_ns = self._time_ns(time)
        R = nearest_rotations(T[:, :3, :3])
        quat = rotation_to_quat_xyzw(R)
        omega = angular_velocities(T[:, :3, :3], V[:, :3, :3])
        stamp = {"sec": t_ns // 1_000_000_000, "nsec": t_ns % 1_000_000_000}

        fm = self._fox.messages
        ts = fm.Timestamp(sec=stamp["sec"], nsec=stamp["nsec"])
        pos, q = T[:, :3, 3].tolist(), quat.tolist()
        tfs = [
            fm.FrameTransform(
                timestamp=ts,
                parent_frame_id="world",
                child_frame_id=frame,
                translation=fm.Vector3(x=p[0], y=p[1], z=p[2]),
                rotation=fm.Quaternion(x=r[0], y=r[1], z=r[2], w=r[3]),
            )
            for frame, p, r in zip(entry.frames, pos, q, strict=True)
        ]
        self._write(entry, "tf", fm.FrameTransforms(transforms=tfs).encode(), t_ns)

        rows_T, rows_V = T[:, :3, :].reshape(n, 12).tolist(), V[:, :3, :].reshape(n, 12).tolist()
        lin, ang = V[:, :3, 3].tolist(), omega.tolist()
        bodies = [
            {
                "name": entry.names[i],
                "frame_id": entry.frames[i],
                "position": pos[i],
                "orientation": q[i],
                "linear_velocity": lin[i],
                "angular_velocity": ang[i],
                "transform": rows_T[i],
                "velocity": rows_V[i],
            }
            for i in range(n)
        ]
        msg = {"timestamp": stamp, "step": int(step), "time": float(time), "bodies": bodies}
        self._write(entry, "bodies", _dumps(msg), t_ns)

    def log_diagnostics(
        self,
        time: float,
        diagnostics: Any,
        *,
        step: int | None = None,
        namespace: str | None = None,
    ) -> None:
        """Log solver diagnostics (a dict, dataclass or object with public attributes)."""
        self._check_open()
        entry = self._namespace(namespace)
        t_ns = self._time_ns(time)
        msg = to_jsonable(diagnostics)
        if not isinstance(msg, dict):
            msg = {"value": msg}
        msg["timestamp"] = _timestamp(t_ns)
        msg["time"] = float(time)
        if step is not None:
            msg.setdefault("step", int(step))
        msg.setdefault("step", max(self._steps[entry.name] - 1, 0))
        self._write(entry, "diagnostics", _dumps(msg), t_ns)

    def log_joints(
        self,
        time: float,
        joints: Sequence[dict[str, Any]],
        *,
        step: int | None = None,
        namespace: str | None = None,
    ) -> None:
        """Log joint states: dicts with ``name``, ``kind``, ``position``, ``velocity``."""
        self._check_open()
        entry = self._namespace(namespace)
        t_ns = self._time_ns(time)
        msg = {"timestamp": _timestamp(t_ns), "joints": to_jsonable(list(joints))}
        msg["step"] = int(step) if step is not None else max(self._steps[entry.name] - 1, 0)
        self._write(entry, "joints", _dumps(msg), t_ns, JOINT_STATES_SCHEMA)

    def log_world(self, world: Any, *, namespace: str | None = None) -> None:
        """Log a World's current time, transforms, velocities and last step's diagnostics.

        The state's ``step`` is ``world.step_count`` (steps taken); the diagnostics message
        carries the World's own fields (its ``step`` is the 0-based index of the last step)
        plus ``min_distance`` where the World reports a minimum contact distance.
        """
        from abdsim.bridges import _world_adapter as adapter

        t = adapter.world_time(world)
        step = adapter.world_step_count(world)
        self.log_state(
            t,
            adapter.world_transforms(world),
            adapter.world_velocities(world),
            step=step,
            namespace=namespace,
        )
        joints = getattr(world, "joints", None)
        if joints:
            q, v = world.joint_positions(), world.joint_velocities()
            states, iq, iv = [], 0, 0
            for j in joints:
                states.append(
                    {
                        "name": j.name,
                        "kind": j.kind,
                        "position": q[iq : iq + j.nq],
                        "velocity": v[iv : iv + j.nv],
                    }
                )
                iq, iv = iq + j.nq, iv + j.nv
            self.log_joints(t, states, step=step, namespace=namespace)
        # Contact forces (NS/contacts, NS/contact_arrows) of Worlds with contact.
        from abdsim.bridges.contact_log import log_world_contacts

        log_world_contacts(self, world, t, step=step, namespace=namespace)
        diag = adapter.world_diagnostics(world)
        if diag is None:
            return
        msg = to_jsonable(diag)
        if not isinstance(msg, dict):
            msg = {"value": msg}
        min_distance = getattr(world, "min_contact_distance", None)
        if callable(min_distance) and "min_distance" not in msg:
            msg["min_distance"] = to_jsonable(min_distance())
        self.log_diagnostics(t, msg, namespace=namespace)

    # -- internals ---------------------------------------------------------------------------
    def _time_ns(self, time: float) -> int:
        t = float(time)
        if not math.isfinite(t) or t < 0:
            raise ValueError(f"time must be finite and >= 0, got {time}")
        return int(round(t * 1e9)) + self.time_offset_ns

    def _log_scene(self, entry, meshes, kinds, time) -> None:
        fm = self._fox.messages
        t_ns = self._time_ns(time)
        ts = fm.Timestamp(sec=t_ns // 1_000_000_000, nsec=t_ns % 1_000_000_000)
        identity = fm.Pose(
            position=fm.Vector3(x=0.0, y=0.0, z=0.0),
            orientation=fm.Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
        )
        entities = []
        for i, mesh in enumerate(meshes):
            if mesh is None:
                continue
            v, f = np.asarray(mesh[0], dtype=np.float64), np.asarray(mesh[1], dtype=np.int64)
            kind = kinds[i] if kinds is not None else "dynamic"
            r, g, b = _KIND_COLOR.get(kind, _PALETTE[i % len(_PALETTE)])
            tri = fm.TriangleListPrimitive(
                pose=identity,
                points=[fm.Point3(x=x, y=y, z=z) for x, y, z in v.tolist()],
                color=fm.Color(r=r, g=g, b=b, a=1.0),
                indices=f.reshape(-1).tolist(),
            )
            entities.append(
                fm.SceneEntity(
                    timestamp=ts,
                    frame_id=entry.frames[i],
                    id=entry.names[i],
                    frame_locked=True,
                    triangles=[tri],
                    metadata=[fm.KeyValuePair(key="kind", value=str(kind))],
                )
            )
        self._write(entry, "scene", fm.SceneUpdate(entities=entities).encode(), t_ns)

    def _check_open(self) -> None:
        if self._closed:
            raise ValueError(f"McapLogger for {self.path} is closed")

    @property
    def namespaces(self) -> dict[str, list[str]]:
        """Registered namespaces and their body names."""
        return {ns: list(e.names) for ns, e in self._namespaces.items()}

    def flush(self) -> None:
        """Finish the current chunk and hand it to the OS (smaller chunks, less at risk)."""
        self._check_open()
        self._writer.flush()

    def checkpoint(self) -> None:
        """Make the file a complete MCAP file now (summary included); logging may go on."""
        self._check_open()
        self._writer.checkpoint()

    def close(self) -> None:
        """Write the summary and close the file (idempotent)."""
        if self._closed:
            return
        self._closed = True
        try:
            self._writer.close()
        finally:
            self._file.close()

    def __enter__(self) -> McapLogger:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:  # pragma: no cover - best effort
        try:
            self.close()
        except Exception:
            pass


#: World -> {resolved path: logger} for ``step_and_log`` (continuing logs across calls).
_WORLD_LOGS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _logger_for(world: Any, log: str | os.PathLike | McapLogger, **options: Any) -> McapLogger:
    if isinstance(log, McapLogger):
        return log
    path = str(Path(log).expanduser().resolve())
    logs = _WORLD_LOGS.setdefault(world, {})
    logger = logs.get(path)
    if logger is None or logger._closed:
        from abdsim.bridges import _world_adapter as adapter

        logger = McapLogger(path, world, **options)
        logger.log_state(
            adapter.world_time(world),
            adapter.world_transforms(world),
            adapter.world_velocities(world),
            step=adapter.world_step_count(world),
        )
        logs[path] = logger
    return logger


def step_and_log(
    world: Any,
    n: int,
    log: str | os.PathLike | McapLogger,
    *,
    driver: Any = None,
    log_every: int = 1,
    progress: bool = False,
    **logger_options: Any,
) -> Any:
    """Step ``world`` ``n`` times, logging to ``log``; returns the last step's diagnostics.

    ``log`` is a path or a :class:`McapLogger`. A path opens a logger (logging the current
    state first) that stays attached to this World: later calls with the same path continue
    the same file. When this returns (or raises) the file is a complete MCAP file;
    :func:`close_logs` (or interpreter exit) releases it. ``driver`` sets the
    kinematic targets before each step; every ``log_every``-th step (and the last) is logged.
    ``world.step(n, log=...)`` calls this.
    """
    from abdsim.bridges import _world_adapter as adapter

    if int(n) != n or int(n) < 1 or int(log_every) < 1:
        raise ValueError(f"need n >= 1 and log_every >= 1, got n={n}, log_every={log_every}")
    logger = _logger_for(world, log, **logger_options)
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=int(n), unit="step")
    try:
        for k in range(int(n)):
            if driver is not None:
                driver.apply(world)
            adapter.world_step(world)
            if (k + 1) % int(log_every) == 0 or k + 1 == int(n):
                logger.log_world(world)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
        # Control goes back to the caller (also on an exception): the file must be complete.
        if not logger._closed:
            logger.checkpoint()
    return adapter.world_diagnostics(world)


def close_logs(world: Any = None) -> None:
    """Finish the logs ``step_and_log`` opened for ``world`` (every World if None)."""
    worlds = [world] if world is not None else list(_WORLD_LOGS.keys())
    for w in worlds:
        for logger in _WORLD_LOGS.pop(w, {}).values():
            logger.close()


atexit.register(close_logs)


def run_and_log(
    world: Any,
    n: int,
    path: str | os.PathLike,
    *,
    driver: Any = None,
    log_every: int = 1,
    **logger_options: Any,
) -> Path:
    """Step ``world`` ``n`` times into a new, finished log at ``path``; returns the path.

    Logs the initial state, then every ``log_every``-th step (and the last): poses, twists
    and the World's diagnostics. ``driver`` (a :class:`~abdsim.bridges.KinematicDriver`)
    sets the kinematic targets before each step. ``logger_options`` go to
    :class:`McapLogger`.
    """
    with McapLogger(path, world, **logger_options) as logger:
        from abdsim.bridges import _world_adapter as adapter

        logger.log_state(
            adapter.world_time(world),
            adapter.world_transforms(world),
            adapter.world_velocities(world),
            step=adapter.world_step_count(world),
        )
        if int(n) > 0:
            step_and_log(world, n, logger, driver=driver, log_every=log_every)
    return Path(path)


# ---------------------------------------------------------------------------------------------
# Rotations, twists, JSON
# ---------------------------------------------------------------------------------------------
def rotation_to_quat_xyzw(R: np.ndarray) -> np.ndarray:
    """Unit quaternions [x, y, z, w] (w >= 0, Foxglove's order) of rotation matrices (n, 3, 3)."""
    return quaternions_wxyz(R)[:, [1, 2, 3, 0]]


def to_jsonable(obj: Any, _depth: int = 0) -> Any:
    """Plain JSON values from dicts, dataclasses, numpy values and objects with attributes.

    A list of ``(str, number)`` pairs becomes a dict (e.g. the solver's named energies);
    NaN and infinities become None (JSON has no such numbers).
    """
    if _depth > 8:
        return repr(obj)
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        f = float(obj)
        return f if math.isfinite(f) else None
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist(), _depth + 1)
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v, _depth + 1) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        if obj and all(
            isinstance(x, (list, tuple)) and len(x) == 2 and isinstance(x[0], str) for x in obj
        ):
            return {k: to_jsonable(v, _depth + 1) for k, v in obj}
        return [to_jsonable(x, _depth + 1) for x in obj]
    fields = getattr(obj, "__dataclass_fields__", None)
    if fields is not None:
        return {k: to_jsonable(getattr(obj, k), _depth + 1) for k in fields}
    attrs = {}
    for k in dir(obj):
        if k.startswith("_"):
            continue
        try:
            v = getattr(obj, k)
        except Exception:
            continue
        if not callable(v):
            attrs[k] = to_jsonable(v, _depth + 1)
    return attrs if attrs else repr(obj)


def _timestamp(t_ns: int) -> dict[str, int]:
    """foxglove.Time of a log time in nanoseconds."""
    return {"sec": t_ns // 1_000_000_000, "nsec": t_ns % 1_000_000_000}


def _dumps(msg: dict[str, Any]) -> bytes:
    return json.dumps(msg, separators=(",", ":"), allow_nan=False).encode("utf-8")


def _abdsim_version() -> str:
    try:
        import abdsim

        return str(abdsim.__version__)
    except Exception:  # pragma: no cover
        return "unknown"
