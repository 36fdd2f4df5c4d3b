"""Simulate an MJCF scene with abdsim and log the run to MCAP (opens in Foxglove).

Run: python examples/log_run.py [SCENE.xml] [-o abdsim_out/run.mcap] [--steps 200]

Loads the scene with abdsim.bridges.load_mjcf (exact MuJoCo mass properties, keyframe poses
and velocities), builds a World, steps it while logging every body's pose and twist plus the
solver's diagnostics, then reads the log back and plots a body's height.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from abdsim.bridges import load_mjcf, read_log, run_and_log

SCENE = Path(__file__).parent / "scenes" / "free_bodies.xml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", type=Path, default=SCENE)
    parser.add_argument("-o", "--output", default="abdsim_out/run.mcap")
    parser.add_argument("--steps", type=int, default=100)
    args = parser.parse_args()

    result = load_mjcf(args.scene)
    print(result)
    world = result.make_world()
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    run_and_log(world, args.steps, args.output)

    log = read_log(args.output)
    print(log)
    name = log.names[int(np.argmax([b.kind == "dynamic" for b in result.bodies]))]
    z = log.field(name, "position")[:, 2]
    print(f"{name}: height {z[0]:.4f} m -> {z[-1]:.4f} m over {log.times[-1]:.2f} s")
    steps = log.diagnostics.get("newton_iterations")
    if steps is not None:
        print(
            f"Newton iterations per step: mean {np.nanmean(steps):.2f}, max {np.nanmax(steps):.0f}"
        )
    print(f"inspect: abdsim log info {args.output}")
    print(f"plot:    abdsim log plot {args.output} --body {name} --field position")


if __name__ == "__main__":
    main()
