"""Robots on the ground: abdsim against MuJoCo on the same URDFs (example-robot-data).

1. A quadruped (go2 or solo12, floating base) standing under position control: in its SRDF
   stance, lowest point 2 mm above the ground, position actuators on all 12 joints holding
   the stance (kp = 2 N·m/rad per kg of robot, kv = kp / 50; the same in MuJoCo).
2. The Panda (fixed base) holding a pose under position actuators (kp = 200, kv = 20),
   without contact.
3. 8 of the quadrupeds on a 4 × 2 grid, dropped together 5 cm onto the ground.

dt = 2e-3, 1 s. Both engines step one step at a time from Python; only the step calls are
timed. Both simulate the same contacts, robot–ground only (``--self-contact``: abdsim's
links also collide with each other, those the loader does not exclude). MuJoCo: the
MuJoCo-ready URDF (``abdsim.validation.robot_mujoco``: free joint, floor, the same gains),
integrator implicitfast (its recommended one for robots: RK4 and Euler are unstable on the
Panda's 15 g fingers with kv = 20; ``--mujoco-integrator RK4`` for the one ``abdsim
validate`` compares with, 4 evaluations a step). Reported:
steps/s of each, abdsim's speed as "N× MuJoCo's speed (> 1 is faster)" by wall clock and by
CPU time (process time of each engine's step calls: steadier than the wall clock on a loaded
machine, where a short MuJoCo step is preempted less often than a long abdsim one), abdsim's
smallest gap (contact distance over every step) and MuJoCo's largest penetration.

Usage: python benchmarks/robots.py [--robot solo12|go2] [--duration 1.0] [--robots 8]
                                  [--self-contact] [--mujoco-integrator RK4]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np

import abdsim
from abdsim.bridges import build_articulated_scene
from abdsim.validation.robot_drop import KAPPA, default_gains, drop_setup, mujoco_penetration
from abdsim.validation.robot_mujoco import add_floor, joint_map, mujoco_robot, mujoco_robot_spec
from abdsim.validation.robot_setup import load_robot
from abdsim.validation.speed import CONVENTION

DT = 2e-3
QUADRUPEDS = {
    "solo12": "solo_description/robots/solo12.urdf",
    "go2": "go2_description/urdf/go2.urdf",
}
PANDA = "panda_description/urdf/panda.urdf"
PANDA_KP, PANDA_KV = 200.0, 20.0
SPACING = 1.0  # m between the dropped robots


def robot_file(relative: str) -> Path:
    for entry in sys.path:
        path = Path(entry or ".") / "cmeel.prefix/share/example-robot-data/robots" / relative
        if path.is_file():
            return path
    raise SystemExit(f"example-robot-data's {relative} is not installed")


def run(world, mj, data, steps: int, integrator: str) -> dict:
    """Step both (MuJoCo with ``integrator``); steps/s of each, abdsim's smallest gap,
    MuJoCo's largest penetration."""
    mj.opt.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{integrator}")
    wall = {"abdsim": 0.0, "mujoco": 0.0}
    cpu = {"abdsim": 0.0, "mujoco": 0.0}
    gap, depth = np.inf, 0.0
    for _ in range(steps):
        t0, c0 = time.perf_counter(), time.process_time()
        d = world.step()
        t1, c1 = time.perf_counter(), time.process_time()
        mujoco.mj_step(mj, data)
        wall["abdsim"] += t1 - t0
        wall["mujoco"] += time.perf_counter() - t1
        cpu["abdsim"] += c1 - c0
        cpu["mujoco"] += time.process_time() - c1
        gap = min(gap, float(d.min_contact_distance))
        depth = max(depth, mujoco_penetration(mj, data))
    return {
        "abdsim": steps / wall["abdsim"],
        "mujoco": steps / wall["mujoco"],
        "cpu_speed": cpu["mujoco"] / cpu["abdsim"],
        "gap": gap,
        "penetration": depth,
    }


def standing(path: Path, out: Path, steps: int, integrator: str, self_contact: bool) -> dict:
    s = drop_setup(path, out, DT, drop_height=2e-3, self_contact=self_contact)
    return run(s.world, s.mj_model, s.mj_data, steps, integrator)


def panda(out: Path, steps: int, integrator: str) -> dict:
    path = robot_file(PANDA)
    result, scene, q = load_robot(
        path, None, floating=False, kappa=1e10, dt=DT, integrator="bdf2", contact=False
    )
    for j in scene.joints:
        scene.add_actuator(j, "position", kp=PANDA_KP, kv=PANDA_KV)  # target: the loaded pose
    jm = joint_map(scene, result.model)
    q_load = jm.pin_positions(q)
    act = [(j.name, PANDA_KP, PANDA_KV) for j in scene.joints]
    loads = dict(zip(jm.names, q_load, strict=True))
    mj, _, _ = mujoco_robot(path, out, scene, loads, actuators=act)
    jm = joint_map(scene, result.model, mj)
    mj.opt.timestep = DT
    data = mujoco.MjData(mj)
    data.qpos[jm.mj_q] = q_load
    data.ctrl[:] = q_load
    row = run(abdsim.World(scene), mj, data, steps, integrator)
    row["gap"] = row["penetration"] = float("nan")  # no contact in this case
    return row


def combine(results: list, self_contact: bool) -> object:
    """One LoadResult holding several robots (bodies, joints and contact rules renumbered;
    joint names prefixed ``r<k>_``) for ``build_articulated_scene``; without
    ``self_contact`` no two robot bodies collide (robot–ground contacts only)."""
    from abdsim.bridges._contact_rules import ContactRules

    bodies, joints, rules = [], [], ContactRules()
    for k, r in enumerate(results):
        n = len(bodies)
        shift = lambda i, n=n: None if i is None else i + n  # noqa: E731
        bodies += [replace(b, parent=shift(b.parent)) for b in r.bodies]
        joints += [
            replace(j, name=f"r{k}_{j.name}", parent=shift(j.parent), child=j.child + n)
            for j in r.joints
        ]
        rules.excluded |= {(i + n, j + n) for i, j in r.contact_rules.excluded}
        rules.ground_excluded |= {i + n for i in r.contact_rules.ground_excluded}
    if not self_contact:
        n = len(bodies)
        rules.excluded |= {(i, j) for i in range(n) for j in range(i + 1, n)}
    return replace(results[0], bodies=bodies, joints=joints, contact_rules=rules, _scene=None)


def dropped_together(
    path: Path, out: Path, steps: int, integrator: str, count: int, self_contact: bool
) -> dict:
    """``count`` robots on a grid, each as ``drop_setup`` places it, dropped together."""
    one = drop_setup(path, out, DT)
    kp, kv = default_gains(one.result)
    base_q = one.result.q
    results, offsets = [], []
    for k in range(count):
        offset = np.array([SPACING * (k % 4), SPACING * (k // 4), 0.0])
        q = base_q.copy()
        q[:3] += offset
        result, _, _ = load_robot(path, q, floating=True, kappa=KAPPA)
        results.append(result)
        offsets.append(offset)
    scene = build_articulated_scene(
        combine(results, self_contact),
        dt=DT,
        integrator="bdf2",
        friction=one.scene.settings.friction,
    )
    scene.add_ground(0.0)
    for j in scene.joints:
        scene.add_actuator(j, "position", kp=kp, kv=kv)
    world = abdsim.World(scene)

    spec = mujoco.MjSpec()
    spec.option.timestep = DT
    add_floor(spec, one.scene.settings.friction)
    loads = dict(zip(one.names, one.q_load, strict=True))
    act = [(n, kp, kv) for n in one.names]
    for k, offset in enumerate(offsets):
        child, _, _ = mujoco_robot_spec(
            path, out, _Joints(one), loads, floating=True, actuators=act, floor=False
        )
        frame = spec.worldbody.add_frame(pos=offset)
        spec.attach(child, prefix=f"r{k}_", frame=frame)
    mj = spec.compile()
    data = mujoco.MjData(mj)
    free = np.flatnonzero(mj.jnt_type == mujoco.mjtJoint.mjJNT_FREE)
    q = base_q
    for k, (f, offset) in enumerate(zip(free, offsets, strict=True)):
        adr = mj.jnt_qposadr[f]
        data.qpos[adr : adr + 3] = q[:3] + offset
        data.qpos[adr + 3 : adr + 7] = [q[6], q[3], q[4], q[5]]
        for name, value in loads.items():
            data.qpos[mj.joint(f"r{k}_{name}").qposadr] = value
    for a in range(mj.nu):
        data.ctrl[a] = data.qpos[mj.jnt_qposadr[mj.actuator_trnid[a, 0]]]
    mujoco.mj_forward(mj, data)
    return run(world, mj, data, steps, integrator)


class _Joints:
    """The 1-dof joints of a ``DropSetup``'s scene (what ``mujoco_robot_spec`` reads)."""

    def __init__(self, setup) -> None:
        self.joints = [j for j in setup.scene.joints if j.kind in ("revolute", "prismatic")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", choices=sorted(QUADRUPEDS), default="solo12")
    parser.add_argument("--duration", type=float, default=1.0)
    parser.add_argument("--robots", type=int, default=8, help="robots dropped together")
    parser.add_argument(
        "--mujoco-integrator", choices=["IMPLICITFAST", "RK4", "EULER"], default="IMPLICITFAST"
    )
    parser.add_argument(
        "--self-contact", action="store_true", help="abdsim's links collide with each other"
    )
    args = parser.parse_args()
    steps = int(round(args.duration / DT))
    path = robot_file(QUADRUPEDS[args.robot])
    out = Path(tempfile.mkdtemp(prefix="abdsim_robots_"))
    n, own, mi = args.robots, args.self_contact, args.mujoco_integrator
    cases = [
        (f"{args.robot} standing, position control", lambda: standing(path, out, steps, mi, own)),
        ("Panda holding a pose", lambda: panda(out, steps, mi)),
        (f"{n} × {args.robot} dropped", lambda: dropped_together(path, out, steps, mi, n, own)),
    ]
    contacts = "robot–ground and robot–robot (abdsim)" if own else "robot–ground only"
    print(
        f"dt = {DT:g} s, {args.duration:g} s, contacts: {contacts}, MuJoCo "
        f"{args.mujoco_integrator}; speed: {CONVENTION}"
    )
    print(
        f"{'case':34s} {'abdsim steps/s':>15s} {'MuJoCo steps/s':>15s} {'speed':>7s} "
        f"{'CPU speed':>9s} {'abdsim min gap (m)':>19s} {'MuJoCo max pen. (m)':>20s}"
    )
    for name, case in cases:
        r = case()
        print(
            f"{name:34s} {r['abdsim']:15.1f} {r['mujoco']:15.0f} {r['abdsim'] / r['mujoco']:6.4f}× "
            f"{r['cpu_speed']:8.4f}× {r['gap']:19.3e} {r['penetration']:20.3e}",
            flush=True,
        )


if __name__ == "__main__":
    main()
