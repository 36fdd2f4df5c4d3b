"""Dense contact: heaps of boxes and a bin of non-convex meshes, abdsim vs MuJoCo (issue 12).

Heaps: N boxes (10 × 8 × 6 cm, 1,000 kg/m³) in 5 layers, each randomly rotated, placed on
a grid with the layers shifted against each other so that they fall onto each other and the
ground. Bin: 30 annuli (outer radius 4 cm, inner 2 cm, 2 cm thick: non-convex) dropped into
a 30 × 30 cm bin (four fixed walls on the ground); MuJoCo, whose mesh collisions use convex
hulls, gets each annulus as 12 convex box pieces around the ring. Both engines step dt = 0.01
for 300 steps (μ = 0.5; abdsim: OrthoPotential, κ = 1e8 Pa, IPC contact with its defaults;
MuJoCo: implicitfast, default soft contact), each inside the engine, one step per call, in
the same run; the table gives steps/s, their ratio, abdsim's median and largest Newton
iteration count per step, abdsim's smallest contact gap (d − ξ over the active pairs, every
step: > 0 means no intersection) and MuJoCo's largest penetration (−min contact.dist).

--profile adds where abdsim's time goes (StepDiagnostics' timers, summed over the run):
Newton iterations per step (with a histogram: the steps in each range of iterations and
their share of all iterations, and where the > 50-iteration tail lies in the run),
line-search cuts (by the CCD bound vs by Armijo halvings), assembly, linear solve (symbolic
analysis + numeric factorisation), CCD step bounds, line search energies, contact set
updates, broad phase (inside the last three), and the cost of one Newton iteration. The
timers cover the accepted solve only: a step whose result was rejected (its straight-line
motion crosses contact, or Newton failed) and redone in substeps spends the rest of its time
in the rejected attempts, so the profile also gives the steps redone in substeps and their
share of the wall time, and the time outside the timers.

--seeds draws other heaps (the layers' rotations), a row each: the heap is chaotic, so a
round-off-level change of the solver moves its Newton iteration count by tens of percent
(100 boxes, 300 steps: 8,433, 9,135 and 10,711 iterations for three round-off variants of
one build); compare builds over several seeds, or by CPU time per Newton iteration.

Usage: python benchmarks/contact_heap.py [--quick] [--sizes 27 100 500] [--no-bin] [--profile]
       [--seeds 0 1 2]
"""

from __future__ import annotations

import argparse
import os
import time

import mujoco
import numpy as np
import trimesh

import abdsim

EXTENTS = np.array([0.10, 0.08, 0.06])
DENSITY = 1e3
DT = 0.01
MU = 0.5
LAYERS = 5
SPACING = 0.15  # > the boxes' diameter (0.141 m): no overlap at the start, any rotation
ANNULUS = {"r_min": 0.02, "r_max": 0.04, "height": 0.02}
BIN_HALF = 0.15  # half width of the bin's inside (m)
WALL = np.array([0.02, 0.34, 0.2])  # wall box extents (thickness, length, height)


def random_rotations(rng: np.random.Generator, n: int) -> np.ndarray:
    """n uniformly random rotation matrices (n, 3, 3), from random unit quaternions."""
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    ).transpose(2, 0, 1)


def heap_poses(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Centres (n, 3) and rotations (n, 3, 3) of the heap: LAYERS layers on a grid, every
    other layer shifted by half a cell so that boxes land on boxes."""
    rng = np.random.default_rng(seed)
    per_layer = int(np.ceil(n / LAYERS))
    side = int(np.ceil(np.sqrt(per_layer)))
    k = np.arange(n)
    layer, slot = k // per_layer, k % per_layer
    shift = 0.5 * SPACING * (layer % 2)
    centres = np.stack(
        [
            SPACING * (slot % side) + shift,
            SPACING * (slot // side) + shift,
            0.08 + SPACING * layer,
        ],
        axis=1,
    )
    return centres, random_rotations(rng, n)


def bin_poses(n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Annuli above the bin: 3 × 3 per layer, 0.1 m apart, randomly rotated."""
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    layer, slot = k // 9, k % 9
    centres = np.stack([0.1 * (slot % 3 - 1), 0.1 * (slot // 3 - 1), 0.06 + 0.09 * layer], axis=1)
    return centres, random_rotations(rng, n)


def wall_poses() -> tuple[np.ndarray, np.ndarray]:
    """The bin's four walls (extents WALL, the long side along y, rotated for ±y)."""
    off = BIN_HALF + WALL[0] / 2
    centres = np.array([[off, 0, 0], [-off, 0, 0], [0, off, 0], [0, -off, 0]], dtype=float)
    centres[:, 2] = WALL[2] / 2
    Rz = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    return centres, np.stack([np.eye(3), np.eye(3), Rz, Rz])


def _instances(sc, centres: np.ndarray, R: np.ndarray) -> None:
    sc.instances.resize(len(centres))
    T = np.tile(np.eye(4), (len(centres), 1, 1))
    T[:, :3, :3] = R
    T[:, :3, 3] = centres
    sc.transforms = T


def abdsim_world(scene_kind: str, n: int, seed: int = 0) -> abdsim.World:
    """The heap of n boxes (its layers' rotations drawn with `seed`), or the bin of n annuli."""
    scene = abdsim.Scene(dt=DT, friction=MU, history_limit=0)
    scene.add_ground(0.0)
    constitution = abdsim.AffineBodyConstitution("OrthoPotential")
    if scene_kind == "heap":
        sc = abdsim.geometry.box(tuple(EXTENTS))
        _instances(sc, *heap_poses(n, seed))
        constitution.apply_to(sc, kappa=1e8, mass_density=DENSITY)
        scene.add(sc)
    else:
        ring = abdsim.geometry.from_trimesh(trimesh.creation.annulus(sections=16, **ANNULUS))
        _instances(ring, *bin_poses(n))
        constitution.apply_to(ring, kappa=1e8, mass_density=DENSITY)
        scene.add(ring)
        walls = abdsim.geometry.box(tuple(WALL))
        _instances(walls, *wall_poses())
        constitution.apply_to(walls, kappa=1e8, mass_density=DENSITY)
        walls.instances["is_fixed"] = np.ones(4, dtype=np.int32)
        scene.add(walls)
    return abdsim.World(scene)


def _quat(R: np.ndarray) -> str:
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, R.ravel())
    return " ".join(f"{v:.17g}" for v in q)


def _annulus_pieces(pieces: int = 12) -> str:
    """The annulus as convex boxes around the ring (MuJoCo collides convex hulls)."""
    r = 0.5 * (ANNULUS["r_min"] + ANNULUS["r_max"])
    half_t = 0.5 * (ANNULUS["r_max"] - ANNULUS["r_min"])
    half_l = r * np.tan(np.pi / pieces)
    geoms = []
    for k in range(pieces):
        a = 2 * np.pi * k / pieces
        geoms.append(
            f'<geom type="box" size="{half_t} {half_l} {ANNULUS["height"] / 2}" '
            f'pos="{r * np.cos(a)} {r * np.sin(a)} 0" euler="0 0 {a}" density="{DENSITY}"/>'
        )
    return "".join(geoms)


def mujoco_model(scene_kind: str, n: int, seed: int = 0):
    bodies = []
    if scene_kind == "heap":
        half = " ".join(str(e / 2) for e in EXTENTS)
        for c, R in zip(*heap_poses(n, seed), strict=True):
            bodies.append(
                f'<body pos="{c[0]} {c[1]} {c[2]}" quat="{_quat(R)}"><freejoint/>'
                f'<geom type="box" size="{half}" density="{DENSITY}"/></body>'
            )
    else:
        ring = _annulus_pieces()
        for c, R in zip(*bin_poses(n), strict=True):
            bodies.append(
                f'<body pos="{c[0]} {c[1]} {c[2]}" quat="{_quat(R)}"><freejoint/>{ring}</body>'
            )
        half = " ".join(str(e / 2) for e in WALL)
        for c, R in zip(*wall_poses(), strict=True):
            bodies.append(
                f'<geom type="box" size="{half}" pos="{c[0]} {c[1]} {c[2]}" quat="{_quat(R)}"/>'
            )
    xml = (
        f'<mujoco><option timestep="{DT}" integrator="implicitfast"/>'
        f'<default><geom friction="{MU} 0.005 0.0001"/></default>'
        f'<size memory="{max(64, n // 2)}M"/><worldbody>'
        f'<geom type="plane" size="0 0 1"/>{"".join(bodies)}</worldbody></mujoco>'
    )
    model = mujoco.MjModel.from_xml_string(xml)
    return model, mujoco.MjData(model)


# StepDiagnostics.profile timers summed by --profile, in the order printed.
TIMERS = (
    ("assembly", "assembly"),
    ("linear_solve", "linear solve"),
    ("ccd", "CCD bounds"),
    ("line_search", "line search"),
    ("contact_update", "contact update"),
    ("broad_phase", "(broad phase)"),
)
COUNTS = ("ccd_cuts", "armijo_halvings", "symbolic_analyses")


def run_abdsim(scene_kind: str, n: int, steps: int, seed: int = 0) -> dict:
    world = abdsim_world(scene_kind, n, seed)
    iterations, gap, wall, cpu, failure = [], np.inf, 0.0, 0.0, ""
    profile = dict.fromkeys([key for key, _ in TIMERS] + list(COUNTS), 0.0)
    profile.update(step=0.0, searches=0, substep_steps=0, substep_time=0.0)
    profile.update(substep_iterations=0, discarded_iterations=0, discarded_time=0.0)
    reasons: dict[str, int] = {}  # why whole steps were split, by kind
    for k in range(steps):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            d = world.step()
        except abdsim.SolverError as e:
            failure = f"failed at step {k}: {str(e)[:90]}"
            break
        wall += time.perf_counter() - t0
        cpu += time.process_time() - c0
        iterations.append(d.newton_iterations)
        gap = min(gap, d.min_contact_distance)
        profile["step"] += d.wall_time
        for key in profile:
            profile[key] += d.profile.get(key, 0.0)
        profile["searches"] += len(d.line_search_alphas)
        if d.substeps > 1:  # the timers hold the last piece only; wall_time holds them all
            profile["substep_steps"] += 1
            profile["substep_time"] += d.wall_time
            profile["substep_iterations"] += d.newton_iterations
            profile["discarded_iterations"] += d.discarded_newton_iterations
            profile["discarded_time"] += d.discarded_time
            kind = substep_kind(d.substep_reason)
            reasons[kind] = reasons.get(kind, 0) + 1
    steps_done = max(len(iterations), 1)
    iterations = iterations or [0]
    return {
        "rate": steps_done / max(wall, 1e-12),
        "cpu_rate": steps_done / max(cpu, 1e-12),
        "steps": steps_done,
        "failure": failure,
        "newton_median": float(np.median(iterations)),
        "newton_max": int(np.max(iterations)),
        "min_gap": gap,
        "iterations": int(np.sum(iterations)),
        "per_step": np.asarray(iterations),
        "profile": profile,
        "substep_reasons": reasons,
    }


def substep_kind(reason: str) -> str:
    """The kind of failure that split a step (StepDiagnostics.substep_reason), in a word."""
    if reason.startswith("Newton did not converge"):
        return "Newton"
    if "crosses a contact surface" in reason:
        return "path crossing"
    if "would invert" in reason or "would collapse" in reason:
        return "inversion"
    return "other"


def run_mujoco(scene_kind: str, n: int, steps: int, seed: int = 0) -> dict:
    model, data = mujoco_model(scene_kind, n, seed)
    penetration, wall, cpu = 0.0, 0.0, 0.0
    for _ in range(steps):
        t0, c0 = time.perf_counter(), time.process_time()
        mujoco.mj_step(model, data)
        wall += time.perf_counter() - t0
        cpu += time.process_time() - c0
        if data.ncon:
            penetration = max(penetration, float(-data.contact.dist[: data.ncon].min()))
    return {"rate": steps / wall, "cpu_rate": steps / max(cpu, 1e-12), "penetration": penetration}


def print_profile(a: dict, steps: int) -> None:
    p = a["profile"]
    iters = max(a["iterations"], 1)
    print(
        f"      Newton iterations {a['iterations'] / steps:.1f}/step; line searches "
        f"{p['searches']}: cut by the CCD bound {p['ccd_cuts']:.0f}, Armijo halvings "
        f"{p['armijo_halvings']:.0f}; symbolic analyses {p['symbolic_analyses']:.0f}"
    )
    parts = "  ".join(
        f"{label} {1e3 * p[key] / steps:.1f} ms ({100 * p[key] / max(p['step'], 1e-12):.0f}%)"
        for key, label in TIMERS
    )
    print(f"      per step {1e3 * p['step'] / steps:.1f} ms: {parts}")
    timed = sum(p[key] for key, _ in TIMERS if key != "broad_phase")
    share = 100 * p["substep_time"] / max(p["step"], 1e-12)
    print(
        f"      outside the timers {1e3 * (p['step'] - timed) / steps:.1f} ms/step; steps redone "
        f"in substeps {p['substep_steps']:.0f} ({share:.0f}% of the wall time)"
    )
    if a["substep_reasons"]:
        why = ", ".join(f"{kind} {count}" for kind, count in sorted(a["substep_reasons"].items()))
        print(f"      why steps were split: {why}")
        print(
            f"      their Newton iterations {p['substep_iterations']:.0f} "
            f"({100 * p['substep_iterations'] / iters:.0f}% of all), of which thrown away "
            f"(rejected whole steps, failed pieces, rounds redone finer) "
            f"{p['discarded_iterations']:.0f} in {p['discarded_time']:.2f} s"
        )
    print(f"      per Newton iteration {1e3 * p['step'] / iters:.2f} ms")
    print_histogram(a["per_step"])


# Bins of the per-step Newton iteration histogram (--profile): the tail (> 50) is split out
# because a few such steps can hold most of the run's iterations.
HISTOGRAM_EDGES = (0, 5, 10, 20, 50, 100, 200, 10**9)


def print_histogram(per_step: np.ndarray) -> None:
    """Steps per bin of Newton iterations, each bin's share of all iterations, and where in
    the run the tail steps (> 50 iterations) lie."""
    total = max(int(per_step.sum()), 1)
    cells = []
    for lo, hi in zip(HISTOGRAM_EDGES[:-1], HISTOGRAM_EDGES[1:], strict=True):
        inside = per_step[(per_step > lo) & (per_step <= hi)]
        label = f"{lo + 1}-{hi}" if hi < 10**9 else f">{lo}"
        cells.append(f"{label}: {len(inside)} ({100 * inside.sum() / total:.0f}%)")
    print(f"      steps by Newton iterations (share of all iterations): {'  '.join(cells)}")
    tail = np.flatnonzero(per_step > 50)
    if len(tail):
        print(
            f"      mean {per_step.mean():.1f}; steps with > 50 iterations: {len(tail)}, from "
            f"step {tail[0]} to {tail[-1]}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="60 steps instead of 300")
    parser.add_argument("--steps", type=int, default=None)
    parser.add_argument("--sizes", type=int, nargs="+", default=[27, 100, 500])
    parser.add_argument("--no-bin", action="store_true", help="skip the bin of meshes")
    parser.add_argument("--bin-size", type=int, default=30)
    parser.add_argument("--profile", action="store_true", help="where abdsim's time goes")
    parser.add_argument(
        "--seeds", type=int, nargs="+", default=[0], help="heaps' rotation seeds (a row each)"
    )
    args = parser.parse_args()
    steps = args.steps or (60 if args.quick else 300)
    cases = [("heap", n, seed) for n in args.sizes for seed in args.seeds]
    if not args.no_bin:
        cases.append(("bin", args.bin_size, 0))
    print(
        f"{steps} steps of h = {DT} s, μ = {MU}, {os.cpu_count()} CPU(s); "
        f"MuJoCo {mujoco.__version__} (implicitfast)"
    )
    header = (
        f"{'scene':>12} | {'abdsim steps/s':>14} {'Newton med':>10} {'(max)':>5} {'(mean)':>6} "
        f"{'min gap (m)':>11} | {'MuJoCo steps/s':>14} {'max pen. (m)':>12} | {'speed':>7} "
        f"{'CPU speed':>9}"
    )
    print(header)
    print("-" * len(header))
    for kind, n, seed in cases:
        a = run_abdsim(kind, n, steps, seed)
        m = run_mujoco(kind, n, steps, seed)
        label = f"{kind} {n}" + (f" s{seed}" if seed else "")
        print(
            f"{label:>12} | {a['rate']:>14.2f} {a['newton_median']:>10.1f} "
            f"{a['newton_max']:>5d} {a['iterations'] / a['steps']:>6.1f} {a['min_gap']:>11.2e} | "
            f"{m['rate']:>14.1f} {m['penetration']:>12.2e} | {a['rate'] / m['rate']:>7.4f} "
            f"{a['cpu_rate'] / m['cpu_rate']:>9.4f}",
            flush=True,
        )
        if a["failure"]:
            print(f"      abdsim {a['failure']}")
        if args.profile:
            print_profile(a, a["steps"])
    print(
        "speed: abdsim runs at N× MuJoCo's speed (> 1 is faster), by wall clock and by the CPU "
        "time of each engine's step calls (steadier on a loaded machine); Newton med/max/mean: "
        "Newton iterations per step; min gap: abdsim's smallest contact gap over every step "
        "(> 0: no intersection); max pen.: MuJoCo's largest penetration"
    )


if __name__ == "__main__":
    main()
