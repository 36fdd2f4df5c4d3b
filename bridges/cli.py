"""``abdsim log ...``: inspect and plot abdsim MCAP logs.

* ``abdsim log info FILE [--json]``: channels, schemas, message counts, time range, bodies.
* ``abdsim log plot FILE --body NAME [--body NAME ...] --field FIELD [--namespace NS ...]
  [-o out.png]``: one body field over time (``position``, ``orientation`` (quaternion
  xyzw), ``velocity`` (linear, world frame), ``angular_velocity`` (world frame),
  ``transform`` (the 12 entries of [A p]), ``transform_rate`` (dT/dt)), or ``--diagnostic
  KEY`` (e.g. ``newton_iterations``, ``energies.total``, ``wall_time``). Repeating
  ``--namespace`` overlays namespaces (e.g. ``/abdsim`` solid, ``/mujoco`` dashed); every
  axis carries its unit.
"""

from __future__ import annotations

import argparse
import json
from typing import Any

from abdsim.bridges.log_plot import FIELDS as _FIELDS


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
    plot.add_argument(
        "--namespace",
        action="append",
        default=[],
        help="topic namespace, e.g. /abdsim (repeat to overlay, e.g. --namespace /abdsim "
        "--namespace /mujoco)",
    )
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
    from abdsim.bridges.log_plot import plot_log

    out = plot_log(
        args.file,
        args.output,
        bodies=args.body,
        field=args.field,
        namespaces=args.namespace or [None],
        diagnostic=args.diagnostic,
    )
    print(out)
    return 0
