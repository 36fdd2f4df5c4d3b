"""``abdsim log ...``: inspect and plot abdsim MCAP logs.

* ``abdsim log info FILE [--json]``: channels, schemas, message counts, time range, bodies.
* ``abdsim log plot FILE --body NAME [--body NAME ...] --field FIELD [-o out.png]``: one
  body field over time (``position``, ``orientation`` (quaternion xyzw), ``velocity``
  (linear, world frame), ``angular_velocity`` (world frame), ``transform`` (the 12 entries of
  [A p]), ``transform_rate`` (dT/dt)), or ``--diagnostic KEY`` (e.g. ``newton_iterations``,
  ``energies.total``, ``wall_time``).
"""

from __future__ import annotations

import argparse
import json
from typing import Any

#: ``--field`` choice -> LogData field (``velocity`` is the linear velocity of the body origin;
#: ``transform_rate`` the 12 entries of dT/dt).
_FIELDS = {
    "position": "position",
    "orientation": "orientation",
    "velocity": "linear_velocity",
    "linear_velocity": "linear_velocity",
    "angular_velocity": "angular_velocity",
    "transform": "transform",
    "transform_rate": "velocity",
}
_COMPONENTS = {
    "position": ("x", "y", "z"),
    "orientation": ("qx", "qy", "qz", "qw"),
    "linear_velocity": ("vx", "vy", "vz"),
    "angular_velocity": ("wx", "wy", "wz"),
    "transform": ("A00", "A01", "A02", "px", "A10", "A11", "A12", "py", "A20", "A21", "A22", "pz"),
}


def add_parser(subparsers: Any) -> Any:
    """Add the ``log`` subcommand to the ``abdsim`` parser."""
    log = subparsers.add_parser("log", help="inspect and plot MCAP logs")
    sub = log.add_subparsers(dest="log_command", metavar="ACTION", required=True)

    info = sub.add_parser("info", help="channels, schemas, message counts, time range, bodies")
    info.add_argument("file", help="an .mcap log")
    info.add_argument("--json", action="store_true", help="print the summary as JSON")
    info.set_defaults(func=_info)

    plot = sub.add_parser("plot", help="plot a body field or a diagnostic over time (PNG)")
    plot.add_argument("file", help="an .mcap log")
    plot.add_argument("--body", action="append", default=[], help="body name (repeatable)")
    plot.add_argument(
        "--field",
        choices=list(_FIELDS),
        default="position",
        help="body field (velocity: linear, world frame; transform_rate: dT/dt)",
    )
    plot.add_argument("--diagnostic", help="plot this diagnostics key instead of a body field")
    plot.add_argument("--namespace", default=None, help="topic namespace, e.g. /abdsim")
    plot.add_argument("-o", "--output", default=None, help="PNG path (default: FILE-BODY.png)")
    plot.set_defaults(func=_plot)
    return log


def _info(args: argparse.Namespace) -> int:
    from abdsim.bridges.log_reader import log_info

    info = log_info(args.file)
    if args.json:
        print(json.dumps(info, indent=2, default=str))
        return 0
    start, end = info["start_ns"], info["end_ns"]
    print(f"file:        {info['path']} ({info['size_bytes']} bytes)")
    print(f"chunks:      {info['chunks']} ({', '.join(info['compression']) or 'none'})")
    if info["corrupted"]:
        print(f"status:      CORRUPTED ({info['error']}; read up to the chunk before it)")
    elif info["truncated"]:
        print("status:      TRUNCATED (read up to the last complete chunk)")
    if start is not None:
        print(
            f"time range:  {start / 1e9:.6f} .. {end / 1e9:.6f} s "
            f"({(end - start) / 1e9:.6f} s, {info['messages']} messages)"
        )
    else:
        print("time range:  (no messages)")
    print("channels:")
    width = max([len(c["topic"]) for c in info["channels"]] + [5])
    for c in info["channels"]:
        print(f"  {c['topic']:<{width}}  {c['messages']:>8} msgs  {c['schema']} ({c['encoding']})")
    for ns, names in info["bodies"].items():
        print(f"bodies {ns} ({len(names)}): {', '.join(names)}")
    return 0


def _plot(args: argparse.Namespace) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from abdsim.bridges.log_reader import read_log

    data = read_log(args.file, namespace=args.namespace)
    if args.diagnostic is None and not args.body:
        raise ValueError(f"give --body NAME (bodies: {data.names}) or --diagnostic KEY")
    fig, ax = plt.subplots(figsize=(8, 4.5), dpi=110)
    if args.diagnostic is not None:
        key = args.diagnostic
        if key not in data.diagnostics:
            raise KeyError(
                f"no diagnostic {key!r} in the log; available: {sorted(data.diagnostics)}"
            )
        ax.plot(data.diagnostics["time"], data.diagnostics[key], label=key)
        ax.set_ylabel(key)
        title, stem = key, key.replace(".", "_")
    else:
        field = _FIELDS[args.field]
        for name in args.body:
            values = data.field(name, field)
            labels = _COMPONENTS.get(field) or [f"[{k}]" for k in range(values.shape[1])]
            for k, label in enumerate(labels):
                ax.plot(data.times, values[:, k], label=f"{name} {label}")
        ax.set_ylabel(args.field.replace("_", " "))
        title, stem = f"{args.field}: {', '.join(args.body)}", "-".join(args.body + [args.field])
    ax.set_xlabel("time (s)")
    ax.set_title(f"{data.path.name} {data.namespace} — {title}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small", ncol=2)
    fig.tight_layout()
    out = args.output or str(data.path.with_name(f"{data.path.stem}-{stem}.png"))
    fig.savefig(out)
    plt.close(fig)
    print(out)
    return 0
