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
joints, no geometry). Reports steps/s of each, their ratio and abdsim's largest joint violation
(a second, step-by-step run).

Usage: python benchmarks/articulated.py [--steps 1000]
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


def run_abdsim(model: pin.Model, q0: np.ndarray, actuated: bool, steps: int):
    scene = abdsim.Scene(dt=DT, integrator="bdf2", contact=False)
    articulation_from_pinocchio(model, q0, scene)
    for j in scene.joints:
        if actuated:
            scene.add_actuator(j, "position", kp=KP, kv=KV)  # target 0: the loaded pose
    world = abdsim.World(scene)
    t0 = time.perf_counter()
    world.step(steps)
    rate = steps / (time.perf_counter() - t0)
    world = abdsim.World(scene)
    worst = 0.0
    for _ in range(steps):
        d = world.step()
        worst = max(worst, d.joint_violation)
    return rate, worst, np.abs(world.joint_positions()).max()


def run_mujoco(model: pin.Model, q0: np.ndarray, actuated: bool, steps: int) -> float:
    m = mujoco.MjModel.from_xml_string(mjcf(model, actuated))
    d = mujoco.MjData(m)
    d.qpos[:] = q0
    if actuated:
        d.ctrl[:] = q0
    t0 = time.perf_counter()
    mujoco.mj_step(m, d, nstep=steps)
    return steps / (time.perf_counter() - t0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1000)
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
        f"{'max violation (m)':>18s} {'max |q - q0|':>13s}"
    )
    for name, model, q0, actuated in cases:
        ours, violation, moved = run_abdsim(model, q0, actuated, args.steps)
        theirs = run_mujoco(model, q0, actuated, args.steps)
        print(
            f"{name:30s} {ours:15.0f} {theirs:15.0f} {ours / theirs:7.3f} {violation:18.2e} "
            f"{moved:13.3f}"
        )


if __name__ == "__main__":
    main()
