"""Contact throughput: N boxes dropped in a grid onto the ground, abdsim vs MuJoCo.

Both simulate the same boxes (0.1 m cubes, 1000 kg/m³; abdsim: 12-triangle surface,
OrthoPotential, κ = 1e8 Pa, IPC contact with its defaults: d̂ = 1 mm, adaptive barrier
stiffness, μ = 0.5, ε_v = 1e-3 m/s) in a square grid 0.2 m apart, each tilted by a random
rotation of up to 10° and released 5 cm above the ground with zero velocity, for 200 steps of
h = 0.01 s (they land after about 0.1 s and then rest). MuJoCo: the same boxes on a plane,
implicitfast, μ = 0.5, default (soft) contact. Both run the whole run inside the engine
(abdsim ``World.step(n)``, MuJoCo ``mj_step(nstep=n)``); a second, step-by-step run of each
measures the smallest distance (abdsim: lowest vertex height above the ground, every step) and
MuJoCo's deepest penetration (``-min contact.dist``, over the run and at its end).

Usage: python benchmarks/contact_pile.py [--quick] [--sizes 10 100 1000] [--max-n 1000]
"""

from __future__ import annotations

import argparse
import os
import time

import mujoco
import numpy as np

import abdsim

SIZE = 0.1
SPACING = 0.2
DENSITY = 1e3
DT = 0.01
MU = 0.5
DROP = 0.05  # initial height of the lowest point above the ground (m), before tilting


def initial_poses(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Centres (n, 3) and rotations (n, 3, 3): a square grid, random tilts up to 10°."""
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(n)))
    idx = np.arange(n)
    axes = rng.normal(size=(n, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = rng.uniform(0.0, np.radians(10.0), size=n)
    R = np.empty((n, 3, 3))
    for k in range(n):
        K = np.array(
            [
                [0, -axes[k, 2], axes[k, 1]],
                [axes[k, 2], 0, -axes[k, 0]],
                [-axes[k, 1], axes[k, 0], 0],
            ]
        )
        R[k] = np.eye(3) + np.sin(angles[k]) * K + (1 - np.cos(angles[k])) * K @ K
    # lift each box so that its lowest corner starts DROP above the ground
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * SIZE / 2
    lowest = (corners @ np.transpose(R, (0, 2, 1)))[:, :, 2].min(axis=1)
    centres = np.stack([SPACING * (idx % side), SPACING * (idx // side), DROP - lowest], axis=1)
    return centres, R


def abdsim_world(n: int, threads: int = 0) -> abdsim.World:
    centres, R = initial_poses(n)
    sc = abdsim.geometry.box((SIZE, SIZE, SIZE))
    sc.instances.resize(n)
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8, mass_density=DENSITY)
    T = np.tile(np.eye(4), (n, 1, 1))
    T[:, :3, :3] = R
    T[:, :3, 3] = centres
    sc.transforms = T
    scene = abdsim.Scene(dt=DT, friction=MU, num_threads=threads, history_limit=0)
    scene.add_ground(0.0)
    scene.add(sc)
    return abdsim.World(scene)


def mujoco_model(n: int):
    centres, R = initial_poses(n)
    half = SIZE / 2
    bodies = []
    for c, r in zip(centres, R, strict=True):
        q = np.empty(4)
        mujoco.mju_mat2Quat(q, r.ravel())
        bodies.append(
            f'<body pos="{c[0]} {c[1]} {c[2]}" quat="{q[0]} {q[1]} {q[2]} {q[3]}"><freejoint/>'
            f'<geom type="box" size="{half} {half} {half}" density="{DENSITY}" '
            f'friction="{MU} 0.005 0.0001"/></body>'
        )
    xml = (
        f'<mujoco><option timestep="{DT}" integrator="implicitfast"/>'
        f'<size memory="{max(64, n // 4)}M"/><worldbody>'
        f'<geom type="plane" size="0 0 1" friction="{MU} 0.005 0.0001"/>'
        f"{''.join(bodies)}</worldbody></mujoco>"
    )
    model = mujoco.MjModel.from_xml_string(xml)
    return model, mujoco.MjData(model)


def run_abdsim(n: int, steps: int) -> dict:
    world = abdsim_world(n)
    t0 = time.perf_counter()
    world.step(steps)
    wall = time.perf_counter() - t0
    # the same run again, step by step, for the distances and iteration counts
    world = abdsim_world(n)
    handle = world.scene.handles[0]
    low, gap, iterations, coupled = np.inf, np.inf, [], []
    for _ in range(steps):
        d = world.step()
        iterations.append(d.newton_iterations)
        coupled.append(d.coupled_bodies)
        low = min(low, float(world.vertices(handle)[..., 2].min()))
        gap = min(gap, d.min_contact_distance)
    return {
        "rate": steps / wall,
        "newton": float(np.mean(iterations)),
        "newton_max": int(np.max(iterations)),
        "coupled": float(np.mean(coupled)),
        "min_distance": low,
        "min_gap": gap,
    }


def run_mujoco(n: int, steps: int) -> dict:
    model, data = mujoco_model(n)
    t0 = time.perf_counter()
    mujoco.mj_step(model, data, steps)
    wall = time.perf_counter() - t0
    model, data = mujoco_model(n)
    penetration, last = 0.0, 0.0
    for _ in range(steps):
        mujoco.mj_step(model, data)
        last = float(-data.contact.dist[: data.ncon].min()) if data.ncon else 0.0
        penetration = max(penetration, last)
    return {"rate": steps / wall, "penetration": penetration, "final_penetration": last}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="50 steps instead of 200")
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 100, 1000])
    parser.add_argument("--max-n", type=int, default=None, help="skip sizes above this")
    parser.add_argument("--steps", type=int, default=None)
    args = parser.parse_args()
    steps = args.steps or (50 if args.quick else 200)
    sizes = [n for n in args.sizes if args.max_n is None or n <= args.max_n]
    print(
        f"{steps} steps of h = {DT} s, {SIZE} m boxes dropped {DROP} m, μ = {MU}, "
        f"{os.cpu_count()} CPU(s); MuJoCo {mujoco.__version__} (implicitfast)"
    )
    header = (
        f"{'N':>5} | {'abdsim steps/s':>14} {'Newton it':>9} {'(max)':>5} {'coupled':>7} "
        f"{'min dist (m)':>12} | {'MuJoCo steps/s':>14} {'max pen. (m)':>12} {'at end':>8} | "
        f"{'speed':>6}"
    )
    print(header)
    print("-" * len(header))
    for n in sizes:
        a = run_abdsim(n, steps)
        m = run_mujoco(n, steps)
        print(
            f"{n:>5} | {a['rate']:>14.1f} {a['newton']:>9.2f} {a['newton_max']:>5d} "
            f"{a['coupled']:>7.1f} {a['min_distance']:>12.2e} | {m['rate']:>14.1f} "
            f"{m['penetration']:>12.2e} {m['final_penetration']:>8.1e} | "
            f"{a['rate'] / m['rate']:>6.3f}",
            flush=True,
        )
    print(
        "speed: abdsim runs at N× MuJoCo's speed (> 1 is faster), stepping only; "
        "Newton it = mean per step; "
        "coupled = bodies in the coupled Newton solve (mean); min dist = lowest vertex above "
        "the ground over every step (> 0: no penetration)"
    )


if __name__ == "__main__":
    main()
