"""MJCF sensors (bridges/mjcf_sensors.py) against MuJoCo on the same scene
(tests/bridges/data/sensors.xml): the layout, the unsupported sensors' notes, every value at
the same state, and the readings along a 1 s run (abdsim BDF2 vs MuJoCo RK4, dt = 1e-3)."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import abdsim
from abdsim.bridges import load_mjcf

UNSUPPORTED = {"hinge_pos", "hinge_vel", "motor_force", "tumbler_com"}


@pytest.fixture
def loaded(data_dir):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_mjcf(data_dir / "sensors.xml")


def readings(world_or_data, names, adr, dim):
    data = world_or_data
    return {n: np.asarray(data[a : a + k]) for n, a, k in zip(names, adr, dim, strict=True)}


def put_mujoco_at(model, data, res, world):
    """MuJoCo's free joints at abdsim's state: the rotation nearest to A, v of the body
    origin (world) and ω in the body frame (MuJoCo's free-joint qvel)."""
    T, V = world.transforms(), world.velocities()
    for root, i in res.source_map.items():
        j = model.body_jntadr[root]
        if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE:
            continue
        qa, va = model.jnt_qposadr[j], model.jnt_dofadr[j]
        U, _, Wt = np.linalg.svd(T[i, :3, :3])
        R = U @ Wt
        x, y, z, w = Rotation.from_matrix(R).as_quat()
        data.qpos[qa : qa + 7] = [*T[i, :3, 3], w, x, y, z]
        Wm = V[i, :3, :3] @ np.linalg.inv(T[i, :3, :3])
        omega = 0.5 * np.array([Wm[2, 1] - Wm[1, 2], Wm[0, 2] - Wm[2, 0], Wm[1, 0] - Wm[0, 1]])
        data.qvel[va : va + 6] = [*V[i, :3, 3], *(R.T @ omega)]
    mujoco.mj_forward(model, data)


def difference(name, a, b):
    if "quat" in name:  # q and −q are the same rotation
        return min(np.abs(a - b).max(), np.abs(a + b).max())
    return np.abs(a - b).max()


def test_layout_matches_mujoco_and_unsupported_sensors_are_named(loaded):
    """sensor_adr / sensor_dim / names are MuJoCo's; joint, actuator and subtree sensors
    keep their slots as NaN in a scene without joints (build_scene) and each is named in the
    notes (tests/bridges/test_mjcf_joint_sensors.py reads the joint ones)."""
    m = loaded.model
    world = abdsim.World(loaded.scene)
    np.testing.assert_array_equal(world.sensor_adr, m.sensor_adr)
    np.testing.assert_array_equal(world.sensor_dim, m.sensor_dim)
    assert world.sensor_names == [m.sensor(i).name for i in range(m.nsensor)]
    assert len(world.sensordata) == m.nsensordata
    r = readings(world.sensordata, world.sensor_names, world.sensor_adr, world.sensor_dim)
    assert {n for n, v in r.items() if np.isnan(v).any()} == UNSUPPORTED
    for name in UNSUPPORTED:
        assert sum(f"sensor {name!r}" in note for note in loaded.notes) == 1
    assert any("build_articulated_scene" in n and "hinge_pos" in n for n in loaded.notes)


def test_every_sensor_matches_mujoco_at_the_same_state(loaded):
    """After 50 steps, MuJoCo put at abdsim's state (mj_forward) reads the same: frames
    (sites of the root and of a welded child, the inertial frame, a geom relative to another
    body) within 1e-8, velocities within 1e-6 (A is a rotation only up to its small strain),
    accelerations within 1e-6 m/s² (BDF2's step acceleration vs MuJoCo's instantaneous one),
    force / torque of free bodies ~0 in both. (Touch is compared at rest, below: at the same
    state MuJoCo's soft contact and abdsim's barrier are at different depths.)"""
    world = abdsim.World(loaded.build_scene(integrator="bdf2"))
    world.step(50)
    m = loaded.model
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    put_mujoco_at(m, d, loaded, world)
    args = (world.sensor_names, world.sensor_adr, world.sensor_dim)
    ours, theirs = readings(world.sensordata, *args), readings(d.sensordata, *args)
    tolerance = {"gyro": 1e-9, "vel": 1e-6, "acc": 1e-6}
    tolerance.update(force=1e-6, torque=1e-6, rester_force=1e-6)
    for name in set(ours) - UNSUPPORTED - {"touch", "rester_acc"}:
        assert difference(name, ours[name], theirs[name]) < tolerance.get(name, 1e-8), name
    # The rester starts 0.5 mm above the ground, inside abdsim's barrier (d̂ = 1 mm) and
    # outside MuJoCo's contact margin: in abdsim it rests there (its accelerometer reads +g),
    # in MuJoCo the same state is a free fall (0). Checked against the closed form.
    np.testing.assert_allclose(ours["rester_acc"], [0.0, 0.0, 9.81], atol=2e-3)


def test_readings_follow_mujoco_over_one_second(loaded):
    """1 s of a tumbling box, both simulators from the same keyframe (abdsim BDF2, MuJoCo
    RK4, dt = 1e-3). After BDF2's start-up (its first step is a BDF1 step; 20 steps): gyro
    within 3e-4 rad/s (|ω| ≈ 3.9 rad/s; BDF2's own error, measured 1.7e-4), accelerometer
    within 1e-4 m/s², frames within 1e-4; free-body force and torque below 1e-6 in both."""
    world = abdsim.World(loaded.build_scene(integrator="bdf2"))
    m = loaded.model
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    args = (world.sensor_names, world.sensor_adr, world.sensor_dim)
    worst: dict[str, float] = {}
    frames = ("imu_pos", "imu_quat", "tag_pos", "tag_quat", "com_quat")
    for k in range(1000):
        world.step()
        mujoco.mj_step(m, d)
        if k < 20:
            continue
        mujoco.mj_forward(m, d)  # sensors at the state after the step
        ours, theirs = readings(world.sensordata, *args), readings(d.sensordata, *args)
        for name in ("gyro", "acc", *frames):
            worst[name] = max(worst.get(name, 0.0), difference(name, ours[name], theirs[name]))
        for name in ("force", "torque"):
            worst[name] = max(worst.get(name, 0.0), np.abs(ours[name]).max())
            assert np.abs(theirs[name]).max() < 1e-6
    assert worst["gyro"] < 3e-4 and worst["acc"] < 1e-4
    assert max(worst[n] for n in frames) < 1e-4
    assert worst["force"] < 1e-6 and worst["torque"] < 1e-6
    print({k: float(f"{v:.1e}") for k, v in worst.items()})


def test_touch_and_accelerometer_of_a_resting_box_match_mujoco(loaded):
    """The 1 kg box resting on the ground (dt = 0.01, 1 s): abdsim's touch sensor reads its
    weight within 1e-6, MuJoCo's within 1 % of abdsim's; both accelerometers read +g and the
    force sensor of the free body ~0."""
    g = 9.81
    world = abdsim.World(loaded.build_scene(dt=0.01, integrator="bdf2"))
    m = loaded.model
    m.opt.timestep = 0.01
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    world.step(100)
    for _ in range(100):
        mujoco.mj_step(m, d)
    mujoco.mj_forward(m, d)
    args = (world.sensor_names, world.sensor_adr, world.sensor_dim)
    ours, theirs = readings(world.sensordata, *args), readings(d.sensordata, *args)
    assert ours["touch"][0] == pytest.approx(g, rel=1e-6)
    assert theirs["touch"][0] == pytest.approx(ours["touch"][0], rel=0.01)
    np.testing.assert_allclose(ours["rester_acc"], [0.0, 0.0, g], atol=1e-6)
    np.testing.assert_allclose(theirs["rester_acc"], [0.0, 0.0, g], atol=1e-3)
    assert np.abs(ours["rester_force"]).max() < 1e-6 * g
    print(f"touch: abdsim {ours['touch'][0]:.9f} N, MuJoCo {theirs['touch'][0]:.9f} N")
