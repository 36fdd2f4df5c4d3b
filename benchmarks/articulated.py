"""Articulated throughput: abdsim (exact joints) vs MuJoCo on the same trees.

1. example-robot-data's Panda (fixed base, 7 revolute + 2 prismatic finger joints) holding
   its pose under position actuators (kp = 200, kv = 20 on every joint) from a non-singular
   configuration.
2. A chain of 50 revolute links (boxes 2 × 2 × 10 cm, 1000 kg/m³, hinges about y) released at
   small alternating angles and swinging under gravity.
Both: dt = 1e-3, 1,000 steps, the whole run inside each engine (abdsim ``World.step(n)``,
MuJoCo ``mj_step(nstep=n)``, implicitfast: Euler is unstable on the Panda's 15 g fingers
with kv = 20), built from one Pinocchio model (abdsim:
``abdsim.bridges.pinocchio_articulation``; MuJoCo: nested bodies with the same inertials and
joints, no geometry). Neither engine evaluates its energies (MuJoCo's mjENBL_ENERGY is off by
default; abdsim's ``SceneSettings.energies`` is turned off here; --energies turns it on).
Reports steps/s of each, their ratio and abdsim's largest joint violation
(a second, step-by-step run). On a shared machine wall-clock rates swing with the load: the
ratio of CPU times (process time of each run) is printed too, and each engine's run is
repeated (--repeat, from the same start), the two engines' runs alternating so that a slow
spell falls on both, with each engine's fastest repetition reported (timeit's rule: the
fastest run is the one least disturbed by the rest of the machine).

--profile adds where abdsim's step goes (StepDiagnostics of the timed run, per step): Newton
iterations, assembly (bodies, shape energy and joint forces), the linear solve (the KKT system:
block-tree elimination for articulations), step bounds, line search, the terms' update, the
rest of the C++ step (prediction, start iterate, constraint projection, diagnostics) and the
Python overhead of ``World.step`` around it.

Usage: python benchmarks/articulated.py [--steps 1000] [--repeat 15] [--profile]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin

import abdsim
from abdsim.bridges.pinocchio_articulation import articulation_from_pinocchio, joint_axis

DT = 1e-3
KP, KV = 200.0, 20.0


def panda_model() -> pin.Model:
    import sys

    for entry in sys.path:
        path = Path(entry or ".") / "cmeel.prefix/share/example-robot-data/robots"
        urdf = path / "panda_description" / "urdf" / "panda.urdf"
        if urdf.is_file():
            return pin.buildModelFromUrdf(str(urdf))
    raise SystemExit("example-robot-data is not installed")


def chain_model(n: int = 50, length: float = 0.1, side: float = 0.02) -> pin.Model:
    model = pin.Model()
    mass = 1e3 * side * side * length
    inertia = pin.Inertia.FromBox(mass, side, side, length)
    inertia = pin.Inertia(mass, np.array([0.0, 0.0, -length / 2]), inertia.inertia)
    parent = 0
    for i in range(n):
        placement = pin.SE3(np.eye(3), np.array([0.0, 0.0, -length if i else 0.0]))
        parent = model.addJoint(parent, pin.JointModelRY(), placement, f"j{i}")
        model.appendBodyToJoint(parent, inertia, pin.SE3.Identity())
    return model


def mjcf(model: pin.Model, actuated: bool) -> str:
    """Nested MuJoCo bodies at Pinocchio's zero configuration, same joints and inertials."""
    children: dict[int, list[int]] = {}
    for i in range(1, model.njoints):
        children.setdefault(model.parents[i], []).append(i)

    def body(i: int) -> str:
        M = model.jointPlacements[i]
        quat = pin.Quaternion(M.rotation)
        kind, axis = joint_axis(model.joints[i])
        inertia, c = model.inertias[i].inertia, model.inertias[i].lever
        pairs = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
        full = " ".join(str(inertia[a, b]) for a, b in pairs)
        inner = "".join(body(k) for k in children.get(i, []))
        return (
            f'<body name="b{i}" pos="{" ".join(map(str, M.translation))}" '
            f'quat="{quat.w} {quat.x} {quat.y} {quat.z}">'
            f'<joint name="j{i}" type="{"hinge" if kind == "revolute" else "slide"}" '
            f'axis="{" ".join(map(str, axis))}"/>'
            f'<inertial pos="{" ".join(map(str, c))}" mass="{model.inertias[i].mass}" '
            f'fullinertia="{full}"/>{inner}</body>'
        )

    act = ""
    if actuated:
        act = "<actuator>" + "".join(
            f'<position joint="j{i}" kp="{KP}" kv="{KV}"/>' for i in range(1, model.njoints)
        )
        act += "</actuator>"
    world = "".join(body(k) for k in children.get(0, []))
    option = f'<option timestep="{DT}" integrator="implicitfast"/>'
    return f"<mujoco>{option}<worldbody>{world}</worldbody>{act}</mujoco>"


# StepDiagnostics.profile timers printed by --profile, in order.
TIMERS = (
    ("assembly", "assembly"),
    ("linear_solve", "linear solve (KKT)"),
    ("ccd", "step bounds"),
    ("line_search", "line search"),
    ("contact_update", "terms' update"),
)


def abdsim_scene(model: pin.Model, q0: np.ndarray, actuated: bool, steps: int, energies: bool):
    scene = abdsim.Scene(dt=DT, integrator="bdf2", contact=False)
    scene.settings.history_limit = steps
    scene.settings.energies = energies
    articulation_from_pinocchio(model, q0, scene)
    for j in scene.joints:
        if actuated:
            scene.add_actuator(j, "position", kp=KP, kv=KV)  # target 0: the loaded pose
    return scene


def time_abdsim(scene: abdsim.Scene, steps: int) -> tuple[float, float, list]:
    """One timed run from the scene's start: wall and CPU seconds, and its diagnostics."""
    world = abdsim.World(scene)
    t0, c0 = time.perf_counter(), time.process_time()
    world.step(steps)
    return time.perf_counter() - t0, time.process_time() - c0, world.history


def time_mujoco(m: mujoco.MjModel, q0: np.ndarray, actuated: bool, steps: int) -> tuple:
    """One timed run of MuJoCo from q0: wall and CPU seconds."""
    d = mujoco.MjData(m)
    d.qpos[:] = q0
    if actuated:
        d.ctrl[:] = q0
    t0, c0 = time.perf_counter(), time.process_time()
    mujoco.mj_step(m, d, nstep=steps)
    return time.perf_counter() - t0, time.process_time() - c0


def compare(
    model: pin.Model, q0: np.ndarray, actuated: bool, steps: int, repeat: int, energies: bool
) -> tuple[dict, dict]:
    """Both engines' fastest of `repeat` runs, the runs alternating (abdsim, MuJoCo, abdsim,
    ...) so that a slow spell of a shared machine falls on both; then abdsim's largest joint
    violation over a step-by-step run."""
    scene = abdsim_scene(model, q0, actuated, steps, energies)
    m = mujoco.MjModel.from_xml_string(mjcf(model, actuated))
    ours = {"wall": float("inf"), "cpu": float("inf")}
    theirs = {"wall": float("inf"), "cpu": float("inf")}
    for _ in range(repeat):
        w, c, history = time_abdsim(scene, steps)
        if c < ours["cpu"]:
            ours.update(wall=w, cpu=c, history=history)
        w, c = time_mujoco(m, q0, actuated, steps)
        if c < theirs["cpu"]:
            theirs.update(wall=w, cpu=c)
    world = abdsim.World(scene)
    worst = 0.0
    for _ in range(steps):
        d = world.step()
        worst = max(worst, d.joint_violation)
    ours.update(
        rate=steps / ours["wall"], violation=worst, moved=np.abs(world.joint_positions()).max()
    )
    theirs["rate"] = steps / theirs["wall"]
    return ours, theirs


def print_profile(run: dict) -> None:
    """Per-step means of the timed run's diagnostics (microseconds of wall-clock time)."""
    history = run["history"]
    n = max(len(history), 1)
    step = sum(d.wall_time for d in history)
    iterations = sum(d.newton_iterations for d in history)
    solver = history[-1].linear_solver
    print(f"    Newton iterations per step {iterations / n:.2f}, linear solver {solver}")
    timed = 0.0
    for key, label in TIMERS:
        seconds = sum(d.profile[key] for d in history)
        timed += seconds
        print(f"    {label:34s} {1e6 * seconds / n:8.1f} us")
    print(f"    {'rest of the C++ step':34s} {1e6 * (step - timed) / n:8.1f} us")
    print(f"    {'Python around World.step':34s} {1e6 * (run['wall'] - step) / n:8.1f} us")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument(
        "--repeat", type=int, default=15, help="runs per engine, alternating (fastest kept)"
    )
    parser.add_argument("--profile", action="store_true", help="where abdsim's step goes")
    parser.add_argument(
        "--energies", action="store_true", help="abdsim evaluates its step-end energies"
    )
    args = parser.parse_args()
    panda = panda_model()
    chain = chain_model()
    cases = [
        (
            "Panda, position actuators",
            panda,
            pin.neutral(panda) + 0.3 * np.sin(np.arange(9) + 1.0),
            True,
        ),
        ("chain of 50 revolute links", chain, 0.05 * (-1.0) ** np.arange(50), False),
    ]
    print(
        f"{'case':30s} {'abdsim steps/s':>15s} {'MuJoCo steps/s':>15s} {'ratio':>7s} "
        f"{'CPU ratio':>9s} {'max violation (m)':>18s} {'max |q - q0|':>13s}"
    )
    for name, model, q0, actuated in cases:
        ours, theirs = compare(model, q0, actuated, args.steps, max(args.repeat, 1), args.energies)
        print(
            f"{name:30s} {ours['rate']:15.0f} {theirs['rate']:15.0f} "
            f"{ours['rate'] / theirs['rate']:7.3f} {theirs['cpu'] / ours['cpu']:9.3f} "
            f"{ours['violation']:18.2e} {ours['moved']:13.3f}"
        )
        if args.profile:
            print_profile(ours)


if __name__ == "__main__":
    main()
