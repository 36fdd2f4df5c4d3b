"""The ``abdsim validate`` subcommand (registered by ``abdsim.cli``)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def _pairs(flag: str):
    """An argparse type reading NAME=NUMBER."""

    def parse(text: str) -> tuple[str, float]:
        name, _, value = text.partition("=")
        try:
            return name, float(value)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{flag}: expected NAME=NUMBER, got {text!r}"
            ) from None

    return parse


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "validate",
        help="run a scene in abdsim, MuJoCo and Pinocchio and compare them",
        description="Cross-validate abdsim against MuJoCo and Pinocchio on an MJCF/URDF scene "
        "(default: the bundled tossed-bodies scene). Writes report.md, metrics.json, PNG plots "
        "and run.mcap to --out; exits non-zero when a tolerance is exceeded.",
    )
    p.add_argument("scene", nargs="?", help="MJCF (.xml) or URDF (.urdf) file")
    p.add_argument("--duration", type=float, default=2.0, help="simulated time [s] (2.0)")
    p.add_argument("--dt", type=float, default=1e-3, help="time step [s] (1e-3)")
    p.add_argument(
        "--out", default="abdsim_out/validation", help="output folder (abdsim_out/validation)"
    )
    p.add_argument("--tolerances", help="JSON/TOML file overriding tolerances")
    p.add_argument("--integrator", choices=["bdf1", "bdf2"], default="bdf2")
    p.add_argument("--no-mcap", action="store_true", help="skip writing run.mcap")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.add_argument(
        "--perturb-inertia",
        type=_pairs("--perturb-inertia"),
        action="append",
        metavar="BODY=FACTOR",
        help="scale a body's inertia in abdsim only (to see the harness fail)",
    )
    robot = p.add_argument_group("URDF robots")
    robot.add_argument(
        "--floating",
        action="store_true",
        help="floating base: drop the robot 5 cm onto the ground under position actuators "
        "holding its stance, against MuJoCo (use --dt 2e-3 --duration 1)",
    )
    robot.add_argument(
        "--self-contact",
        action="store_true",
        help="the dropped robot's links collide with each other in abdsim (MuJoCo's do not)",
    )
    robot.add_argument(
        "--friction", type=float, help="foot–ground friction of the dropped robot (1.0)"
    )
    robot.add_argument("--kp", type=float, help="position gain of the dropped robot's joints")
    robot.add_argument("--kv", type=float, help="velocity gain of the dropped robot's joints")
    for flag, meta, what in (
        ("--perturb-mass", "LINK=FACTOR", "scale a link's mass and inertia"),
        ("--perturb-anchor", "JOINT=METRES", "move a joint's anchor across its axis"),
        ("--perturb-axis", "JOINT=RADIANS", "tilt a joint's axis"),
    ):
        robot.add_argument(
            flag,
            type=_pairs(flag),
            action="append",
            metavar=meta,
            help=f"{what} in abdsim only (to see the robot checks fail)",
        )
    p.add_argument(
        "--sweep",
        action="store_true",
        help="validate every bundled scene (or SCENE) at several time steps in parallel processes",
    )
    p.add_argument("--sweep-dt", type=float, nargs="+", default=[1e-3, 2e-3])
    p.add_argument("--workers", type=int, default=None, help="processes for --sweep")
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run --sweep on an existing Dask scheduler (e.g. tcp://10.0.0.5:8786) instead of "
        "local processes",
    )
    p.add_argument(
        "--list-tolerances", action="store_true", help="print the default tolerances and exit"
    )
    p.set_defaults(func=run)
    return p


def _robot_options(args: argparse.Namespace) -> dict:
    """The URDF-robot options given on the command line (``validate(robot=...)``)."""
    options: dict = {}
    for key in ("perturb_mass", "perturb_anchor", "perturb_axis"):
        if getattr(args, key):
            options[key] = dict(getattr(args, key))
    for key in ("kp", "kv", "friction", "self_contact"):
        if getattr(args, key) not in (None, False):
            if not args.floating:
                flag = "--" + key.replace("_", "-")
                raise ValueError(f"{flag} applies to the dropped robot: add --floating")
            options[key] = getattr(args, key)
    return options


def run(args: argparse.Namespace) -> int:
    from abdsim.validation.tolerances import Tolerances

    if args.list_tolerances:
        print(json.dumps(Tolerances().as_dict(), indent=2))
        return 0
    if args.scheduler and not args.sweep:
        raise ValueError("--scheduler runs a --sweep: add --sweep")
    if args.sweep:
        from abdsim.validation.sweep import default_cases, run_sweep, summary_table

        cases = default_cases(
            args.out, args.duration, tuple(args.sweep_dt), [args.scene] if args.scene else None
        )
        if args.scheduler:
            from dask.distributed import Client

            with Client(args.scheduler) as client:
                rows = run_sweep(cases, executor=client.get_executor(), progress=not args.quiet)
        else:
            rows = run_sweep(cases, max_workers=args.workers, progress=not args.quiet)
        table = summary_table(rows)
        Path(args.out).mkdir(parents=True, exist_ok=True)
        (Path(args.out) / "sweep.md").write_text(table + "\n")
        print(table)
        return 0 if all(r["passed"] for r in rows) else 1

    from abdsim.validation.harness import validate
    from abdsim.validation.speed import describe

    res = validate(
        args.scene,
        duration=args.duration,
        dt=args.dt,
        out=args.out,
        tolerances=args.tolerances,
        integrator=args.integrator,
        progress=not args.quiet,
        mcap=not args.no_mcap,
        perturb_inertia=dict(args.perturb_inertia or []),
        floating=args.floating,
        robot=_robot_options(args),
    )
    n_fail = len(res.failed)
    print(
        f"{'PASSED' if res.passed else 'FAILED'}: {len(res.checks) - n_fail}/{len(res.checks)} "
        f"checks within tolerance"
    )
    for c in res.failed[:10]:
        print(
            f"  ✗ {c.name} [{c.body}]: {c.value:.3g} (limit {c.kind} {c.limit:.3g})",
            file=sys.stderr,
        )
    t = res.metrics["timing"]
    if t:
        sims = t["simulators"]
        for label, key, rate in (
            ("stepping only", "speed_vs_mujoco", "steps_per_s"),
            ("end to end", "speed_vs_mujoco_end_to_end", "end_to_end_steps_per_s"),
        ):
            if key not in t:
                continue
            ratio = t[key]
            print(
                f"{describe(ratio, label)}: abdsim {sims['abdsim'][rate]:.0f} steps/s, "
                f"MuJoCo {sims['mujoco'][rate]:.0f} steps/s"
            )
    for note in res.metrics.get("notes", []):
        print(f"note: {note}")
    print(f"report: {res.report}")
    return 0 if res.passed else 1
