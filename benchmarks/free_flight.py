"""Free-flight throughput: N spinning boxes under gravity, no contact, abdsim vs MuJoCo.

Both simulate the same boxes (0.4 x 0.2 x 0.1 m, 1000 kg/m³; abdsim: 12-triangle surface,
OrthoPotential, κ = 1e8 Pa) with the same initial angular velocities (N(0, 2 rad/s) per
axis) and time step (h = 0.01 s, MuJoCo implicitfast, contype = conaffinity = 0). abdsim runs
its default settings (BDF1, Newton to 0.01 m/s / 0.1 1/s) with OpenMP on the default threads
and on one thread; MuJoCo is single-threaded. Steps run inside each engine (abdsim
``World.step(n)``, MuJoCo ``mj_step(nstep=n)``); the best of a few repeats is reported.

Usage: python benchmarks/free_flight.py [--quick] [--sizes 1 100 1000 10000]
"""

from __future__ import annotations

import argparse
import os
import time

import mujoco
import numpy as np

import abdsim

EXTENTS = np.array([0.4, 0.2, 0.1])
DENSITY = 1e3
DT = 0.01


def initial_conditions(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(n)))
    idx = np.arange(n)
    positions = np.stack([idx % side, idx // side, np.full(n, 10.0)], axis=1) * [1.0, 1.0, 1.0]
    omega_body = rng.normal(scale=2.0, size=(n, 3))
    return positions, omega_body


def abdsim_world(n: int, threads: int) -> abdsim.World:
    positions, omega_body = initial_conditions(n)
    sc = abdsim.geometry.box(tuple(EXTENTS))
    sc.instances.resize(n)
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8, mass_density=DENSITY)
    T = np.tile(np.eye(4), (n, 1, 1))
    T[:, :3, 3] = positions
    sc.transforms = T
    V = np.zeros((n, 4, 4))
    # A = I, so the world angular velocity is the body one and Ȧ = [ω]×.
    w = omega_body
    V[:, 0, 1], V[:, 0, 2], V[:, 1, 2] = -w[:, 2], w[:, 1], -w[:, 0]
    V[:, 1, 0], V[:, 2, 0], V[:, 2, 1] = w[:, 2], -w[:, 1], w[:, 0]
    sc.instances["velocity"] = V
    scene = abdsim.Scene(dt=DT, num_threads=threads, history_limit=0)
    scene.add(sc)
    return abdsim.World(scene)


def mujoco_model(n: int):
    positions, omega_body = initial_conditions(n)
    half = EXTENTS / 2
    bodies = "".join(
        f'<body pos="{p[0]} {p[1]} {p[2]}"><freejoint/>'
        f'<geom type="box" size="{half[0]} {half[1]} {half[2]}" density="{DENSITY}" '
        'contype="0" conaffinity="0"/></body>'
        for p in positions
    )
    memory = f"{max(64, n // 10)}M"
    xml = (
        f'<mujoco><option timestep="{DT}" integrator="implicitfast"/>'
        f'<size memory="{memory}"/><worldbody>{bodies}</worldbody></mujoco>'
    )
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qvel.reshape(n, 6)[:, 3:] = omega_body  # free joint: [v_world, ω_body]
    return model, data


def best_rate(run, steps: int, repeats: int) -> float:
    """Steps per second, best of `repeats` timed runs of `steps` steps."""
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        run(steps)
        best = min(best, time.perf_counter() - t0)
    return steps / best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="short run (fewer steps/repeats)")
    parser.add_argument("--sizes", type=int, nargs="+", default=[1, 100, 1000, 10000])
    args = parser.parse_args()
    budget = 2e4 if args.quick else 2e5  # body-steps per timed run
    repeats = 2 if args.quick else 3
    threads = os.cpu_count() or 1
    print(f"h = {DT} s, boxes {EXTENTS.tolist()} m, {threads} CPU(s); MuJoCo {mujoco.__version__}")
    header = (
        f"{'N':>6} | {'abdsim steps/s':>14} {'body-steps/s':>13} {'(1 thread)':>12} | "
        f"{'MuJoCo steps/s':>14} {'body-steps/s':>13} | {'speed':>6} {'(1 thr)':>7} | "
        f"{'Newton it':>9} {'|AAᵀ-I|':>8}"
    )
    print(header)
    print("-" * len(header))
    for n in args.sizes:
        steps = int(max(10, budget // n))
        world = abdsim_world(n, threads=0)
        world.step(2)
        rate = best_rate(world.step, steps, repeats)
        d = world.diagnostics
        A = world.q[:, 3:].reshape(-1, 3, 3)
        orth = np.abs(A @ np.transpose(A, (0, 2, 1)) - np.eye(3)).max()
        world1 = abdsim_world(n, threads=1)
        world1.step(2)
        rate1 = best_rate(world1.step, steps, repeats)
        model, data = mujoco_model(n)
        mujoco.mj_step(model, data, 2)
        mj_rate = best_rate(lambda k, m=model, dd=data: mujoco.mj_step(m, dd, k), steps, repeats)
        ratio, ratio1 = rate / mj_rate, rate1 / mj_rate
        print(
            f"{n:>6} | {rate:>14.0f} {rate * n:>13.3g} {rate1 * n:>12.3g} | "
            f"{mj_rate:>14.0f} {mj_rate * n:>13.3g} | {ratio:>6.2f} {ratio1:>7.2f} | "
            f"{d.total_body_iterations / n:>9.2f} {orth:>8.1e}"
        )
    print(
        "speed: abdsim runs at N× MuJoCo's speed (> 1 is faster), stepping only; "
        "Newton it = per body, last step"
    )


if __name__ == "__main__":
    main()
