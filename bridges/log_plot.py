"""Figures of abdsim MCAP logs (``abdsim log plot``): a body field or a diagnostic over time,
with units, overlaying several namespaces (e.g. ``/abdsim`` and ``/mujoco``) for one body."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

#: ``--field`` choice -> LogData field (``velocity`` is the linear velocity of the body origin;
#: ``transform_rate`` the 12 entries of dT/dt).
FIELDS = {
    "position": "position",
    "orientation": "orientation",
    "velocity": "linear_velocity",
    "linear_velocity": "linear_velocity",
    "angular_velocity": "angular_velocity",
    "transform": "transform",
    "transform_rate": "velocity",
}
#: Axis label (with unit) of each LogData field.
FIELD_LABELS = {
    "position": "position [m]",
    "orientation": "orientation quaternion (x, y, z, w) [1]",
    "linear_velocity": "linear velocity, world frame [m/s]",
    "angular_velocity": "angular velocity, world frame [rad/s]",
    "transform": "transform entries: A [1], p [m]",
    "velocity": "dT/dt entries: Ȧ [1/s], ṗ [m/s]",
}
_COMPONENTS = {
    "position": ("x", "y", "z"),
    "orientation": ("qx", "qy", "qz", "qw"),
    "linear_velocity": ("vx", "vy", "vz"),
    "angular_velocity": ("wx", "wy", "wz"),
    "transform": ("A00", "A01", "A02", "px", "A10", "A11", "A12", "py", "A20", "A21", "A22", "pz"),
}
#: Units of the diagnostics abdsim logs (others are shown as "[as logged]").
DIAGNOSTIC_UNITS = {
    "time": "s",
    "wall_time": "s",
    "newton_iterations": "count",
    "step": "count",
    "min_distance": "m",
    "min_contact_distance": "m",
    "contact_pairs": "count",
}
_STYLES = ("-", "--", ":", "-.")


def diagnostic_label(key: str) -> str:
    """``"energies.kinetic [J]"``: the key with its unit."""
    if key.startswith("energies."):
        return f"{key} [J]"
    return f"{key} [{DIAGNOSTIC_UNITS.get(key, 'as logged')}]"


def log_figure(
    path: str | os.PathLike,
    bodies: Sequence[str] = (),
    field: str = "position",
    namespaces: Sequence[str | None] = (None,),
    diagnostic: str | None = None,
) -> Any:
    """A matplotlib Figure of one body field (per body and namespace) or one diagnostic.

    Each namespace gets its own line style, each component its own colour, so ``/abdsim``
    (solid) and ``/mujoco`` (dashed) of one body overlay directly.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from abdsim.bridges.log_reader import read_log

    logs = [read_log(path, namespace=ns) for ns in (namespaces or [None])]
    if diagnostic is None and not bodies:
        raise ValueError(f"give --body NAME (bodies: {logs[0].names}) or --diagnostic KEY")
    if diagnostic is None and field not in FIELDS:
        raise KeyError(f"unknown field {field!r}; choose one of {list(FIELDS)}")
    fig, ax = plt.subplots(figsize=(8, 4.5), dpi=110)
    for k, data in enumerate(logs):
        style = _STYLES[k % len(_STYLES)]
        if diagnostic is not None:
            if diagnostic not in data.diagnostics:
                raise KeyError(
                    f"no diagnostic {diagnostic!r} in {data.namespace}; available: "
                    f"{sorted(data.diagnostics)}"
                )
            t = data.diagnostics["time"]
            ax.plot(t, data.diagnostics[diagnostic], style, label=f"{data.namespace}")
            continue
        name = FIELDS[field]
        for body in bodies:
            values = data.field(body, name)
            labels = _COMPONENTS.get(name) or [f"[{j}]" for j in range(values.shape[1])]
            for j, label in enumerate(labels):
                ax.plot(
                    data.times,
                    values[:, j],
                    style,
                    color=f"C{j % 10}",
                    label=f"{data.namespace} {body} {label}",
                )
    ax.set_xlabel("simulated time [s]")
    if diagnostic is not None:
        ax.set_ylabel(diagnostic_label(diagnostic))
        what = diagnostic
    else:
        ax.set_ylabel(FIELD_LABELS[FIELDS[field]])
        what = f"{field}: {', '.join(bodies)}"
    spaces = " vs ".join(d.namespace for d in logs)
    ax.set_title(f"{Path(path).name} {spaces} — {what}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small", ncol=2)
    fig.tight_layout()
    return fig


def plot_log(
    path: str | os.PathLike,
    output: str | os.PathLike | None = None,
    **options: Any,
) -> Path:
    """Save :func:`log_figure` as a PNG (default ``FILE-WHAT.png`` beside the log)."""
    import matplotlib.pyplot as plt

    fig = log_figure(path, **options)
    if output is None:
        p = Path(path)
        diagnostic = options.get("diagnostic")
        stem = (
            diagnostic.replace(".", "_")
            if diagnostic
            else "-".join([*options.get("bodies", ()), options.get("field", "position")])
        )
        output = p.with_name(f"{p.stem}-{stem}.png")
    fig.savefig(output)
    plt.close(fig)
    return Path(output)
