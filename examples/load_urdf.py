"""Load a URDF robot as affine bodies, drive it along a joint trajectory, log it for Foxglove.

Run: python examples/load_urdf.py [URDF] [-o abdsim_out/robot.mcap]

Without an argument it loads the Franka Panda of example-robot-data. Every body's mass
properties are compared with Pinocchio's, then the kinematic links follow a smooth joint
trajectory through Pinocchio's forward kinematics and the poses are written to an MCAP file
(open it in Foxglove: the 3D panel shows the robot moving, no setup needed).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import abdsim
from abdsim.bridges import McapLogger, RobotDriver, example_robot, load_urdf


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("urdf", nargs="?", type=Path, default=None)
    parser.add_argument("-o", "--output", default="abdsim_out/robot.mcap")
    parser.add_argument("--duration", type=float, default=4.0)
    args = parser.parse_args()

    result = load_urdf(args.urdf or example_robot("panda"), kinematic=True)  # scripted links
    model = result.model
    print(result)
    print(f"{'body':<20} {'kind':<10} {'mass [kg]':>10} {'|Δ inertia|':>12}  links")
    for j, i in result.source_map.items():
        body = result.bodies[i]
        rb = abdsim.to_rigid_body(body.geometry)
        ref = model.inertias[j]
        err = np.abs(rb.inertia - ref.inertia).max() if ref.mass > 0 else float("nan")
        links = ", ".join(body.links)
        print(f"{body.name:<20} {body.kind:<10} {rb.mass:>10.4f} {err:>12.2e}  {links}")

    # A smooth joint trajectory around the neutral configuration, sampled at 100 Hz.
    dt = 0.01
    times = np.arange(0.0, args.duration + dt / 2, dt)
    q0 = np.array(result.q)
    amplitude = 0.4 * np.ones(model.nv)
    samples = np.array(
        [
            q0 + amplitude * np.sin(2 * np.pi * 0.25 * t + np.arange(model.nv))[: model.nq]
            for t in times
        ]
    )
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    samples = np.clip(
        samples, np.where(np.isfinite(lo), lo, -np.inf), np.where(np.isfinite(hi), hi, np.inf)
    )
    driver = RobotDriver(result, samples, times=times)

    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    with McapLogger(args.output, result) as log:
        for t in times:
            poses = result.transforms()
            T, V = driver.targets(t)
            poses[driver.bodies] = T
            velocities = np.zeros_like(poses)
            velocities[driver.bodies] = V
            log.log_state(t, poses, velocities)
    print(
        f"wrote {args.output}: {len(times)} states of {len(result.bodies)} bodies "
        f"(try: abdsim log info {args.output})"
    )


if __name__ == "__main__":
    main()
