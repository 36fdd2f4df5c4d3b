"""Loaded scenes, drivers and logs together with a World.

``StandInWorld`` implements the part of ``abdsim.World``'s API that bridges use (ballistic
motion, kinematic targets and schedules), so the wiring is tested on its own; the tests at the
end run the real ``abdsim.World`` when this abdsim has one.
"""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from abdsim.bridges import (
    McapLogger,
    RobotDriver,
    _world_adapter,
    close_logs,
    load_mjcf,
    load_urdf,
    read_log,
    run_and_log,
    step_and_log,
)
from abdsim.bridges._world_adapter import describe_bodies

HAS_WORLD = hasattr(abdsim, "World") and hasattr(abdsim, "Scene")


class StandInScene:
    def __init__(self, geometries, dt=0.01):
        self.geometries = list(geometries)
        self.dt = dt


class StandInWorld:
    """Free flight without rotation; kinematic bodies jump to their targets."""

    def __init__(self, result, dt=0.01):
        self.scene = StandInScene(result.geometries, dt)
        _world_adapter._SOURCES[self.scene] = result  # what build_scene does for a Scene
        self._T = result.transforms()
        self._V = np.array([b.velocity for b in result.bodies])
        self._fixed = np.array([b.kind == "fixed" for b in result.bodies])
        self._targets: dict[int, np.ndarray] = {}
        self._schedules = {}
        self.time, self.step_count, self.diagnostics = 0.0, 0, None

    def transforms(self):
        return self._T.copy()

    def velocities(self):
        return self._V.copy()

    def set_kinematic_targets(self, bodies, transforms):
        for b, T in zip(bodies, transforms, strict=True):
            self._targets[int(b)] = np.array(T)

    def set_kinematic_schedule(self, body, schedule):
        self._schedules[int(body)] = schedule

    def step(self, n=1):
        for _ in range(n):
            dt = self.scene.dt
            for b, f in self._schedules.items():
                self._targets[b] = np.asarray(f(self.time + dt))
            free = ~self._fixed
            free[list(self._targets)] = False
            self._V[free, 2, 3] -= 9.81 * dt
            self._T[free, :3, 3] += dt * self._V[free, :3, 3]
            for b, T in self._targets.items():
                self._V[b] = (T - self._T[b]) / dt
                self._T[b] = T
            self.time += dt
            self.step_count += 1
            self.diagnostics = {"newton_iterations": 1, "energies": {"total": float(self.time)}}


def test_logged_run_equals_the_world_at_every_step(tmp_path, scenes_dir):
    res = load_mjcf(scenes_dir / "free_bodies.xml")
    world = StandInWorld(res)
    expected = []
    run_and_log(world, 0, tmp_path / "empty.mcap")  # only the initial state
    assert len(read_log(tmp_path / "empty.mcap").times) == 1
    with McapLogger(tmp_path / "run.mcap", world) as log:
        log.log_world(world)
        expected.append(world.transforms())
        for _ in range(25):
            world.step()
            log.log_world(world)
            expected.append(world.transforms())
    data = read_log(tmp_path / "run.mcap")
    assert data.names == res.names  # names come from the LoadResult the bodies came from
    np.testing.assert_array_equal(data.transforms, np.array(expected))
    np.testing.assert_array_equal(data.steps, np.arange(26))
    np.testing.assert_allclose(data.times, 0.01 * np.arange(26), atol=1e-15)
    np.testing.assert_array_equal(data.diagnostics["newton_iterations"], np.ones(25))


def test_step_and_log_continues_one_file_per_world(tmp_path, scenes_dir):
    res = load_mjcf(scenes_dir / "free_bodies.xml")
    world = StandInWorld(res)
    step_and_log(world, 10, tmp_path / "a.mcap")
    T10 = world.transforms()
    step_and_log(world, 5, tmp_path / "a.mcap", log_every=5)
    close_logs(world)
    data = read_log(tmp_path / "a.mcap")
    assert not data.truncated
    np.testing.assert_array_equal(data.steps, list(range(11)) + [15])
    np.testing.assert_array_equal(data.transforms[10], T10)
    np.testing.assert_array_equal(data.transforms[-1], world.transforms())
    with pytest.raises(ValueError, match="n >= 1"):
        step_and_log(world, 0, tmp_path / "b.mcap")


def test_driver_applies_and_attaches_to_a_world(tmp_path, data_dir):
    res = load_urdf(data_dir / "arm.urdf", kinematic=True)
    traj = np.array([[0.0, 0.0], [1.0, 0.04]])
    driver = RobotDriver(res, traj, times=[0.0, 0.1])
    world = StandInWorld(res)
    run_and_log(world, 10, tmp_path / "arm.mcap", driver=driver)
    data = read_log(tmp_path / "arm.mcap")
    for k in range(11):
        T, _ = driver.targets(0.01 * k)
        np.testing.assert_allclose(data.transforms[k, 1:], T, atol=1e-15)
    np.testing.assert_array_equal(data.transforms[:, 0], np.tile(res.transforms()[0], (11, 1, 1)))
    attached = StandInWorld(res)
    driver.attach(attached)
    attached.step(7)
    np.testing.assert_allclose(attached.transforms()[1:], driver.targets(0.07)[0], atol=1e-15)


def test_floating_base_limbs_follow_the_simulated_base(data_dir):
    res = load_urdf(data_dir / "arm.urdf", floating_base=True, kinematic=True)
    q = np.array(res.q)
    driver = RobotDriver(res, q[None])
    world = StandInWorld(res)
    driver.attach(world)
    world.step(20)  # the base falls, the limbs keep their pose relative to it
    T = world.transforms()
    rel = np.linalg.inv(T[0]) @ T[1:]
    rel0 = np.linalg.inv(res.transforms()[0]) @ res.transforms()[1:]
    # The base is extrapolated with its velocity over the step: off by g dt² at most.
    np.testing.assert_allclose(rel, rel0, atol=1.01 * 9.81 * 0.01**2)
    assert T[0, 2, 3] < res.transforms()[0, 2, 3] - 0.15


def test_describe_bodies_of_plain_geometries():
    sc = abdsim.geometry.box(0.1)
    sc.instances.resize(2)
    abdsim.AffineBodyConstitution().apply_to(sc, kappa=1e8)
    sc.instances["is_fixed"] = np.array([1, 0], dtype=np.int32)
    bodies = describe_bodies([sc])
    assert [(b.name, b.kind) for b in bodies] == [("body0", "fixed"), ("body1", "dynamic")]
    with pytest.raises(TypeError, match="cannot find the bodies"):
        describe_bodies(object())


def test_scene_needs_abdsim_scene_or_says_so(scenes_dir):
    res = load_mjcf(scenes_dir / "free_bodies.xml")
    if HAS_WORLD:
        assert res.scene is res.scene
    else:
        with pytest.raises(RuntimeError, match="abdsim.Scene is not available"):
            res.scene  # noqa: B018


def test_anchor_prediction_is_exact_for_a_constant_twist():
    from scipy.spatial.transform import Rotation

    from abdsim.bridges.drivers import predict_poses

    w, v = np.array([0.3, -2.0, 1.1]), np.array([1.0, 2.0, -0.5])
    R0 = Rotation.from_rotvec([0.2, 0.4, -0.1]).as_matrix()
    T = np.eye(4)[None].copy()
    T[0, :3, :3], T[0, :3, 3] = R0, [0.5, 0.0, 1.0]
    V = np.zeros((1, 4, 4))
    V[0, :3, :3], V[0, :3, 3] = np.cross(w, R0.T).T, v
    P = predict_poses(T, V, 0.05)[0]
    np.testing.assert_allclose(
        P[:3, :3], Rotation.from_rotvec(0.05 * w).as_matrix() @ R0, atol=1e-14
    )
    np.testing.assert_allclose(P[:3, 3], [0.5, 0.0, 1.0] + 0.05 * v, atol=1e-15)


# -- the real World ----------------------------------------------------------------------------
needs_world = pytest.mark.skipif(not HAS_WORLD, reason="this abdsim has no Scene/World yet")


@needs_world
def test_real_world_logged_run_equals_world_transforms_at_every_step(tmp_path, scenes_dir):
    res = load_mjcf(scenes_dir / "free_bodies.xml", kinematic=True)
    world = res.make_world()
    assert world.scene.dt == res.dt and np.array_equal(world.scene.gravity, res.gravity)
    np.testing.assert_array_equal(world.transforms(), res.transforms())
    expected_T, expected_V = [world.transforms()], [world.velocities()]
    with McapLogger(tmp_path / "run.mcap", world) as log:
        log.log_world(world)
        for _ in range(15):
            world.step()
            log.log_world(world)
            expected_T.append(world.transforms())
            expected_V.append(world.velocities())
    data = read_log(tmp_path / "run.mcap")
    assert data.names == res.names
    np.testing.assert_array_equal(data.transforms, np.array(expected_T))
    np.testing.assert_array_equal(data.velocities, np.array(expected_V))
    np.testing.assert_allclose(data.times, res.dt * np.arange(16), rtol=1e-12, atol=1e-15)
    assert (data.diagnostics["newton_iterations"] >= 1).all()
    # The fixed ramp and the (undriven) kinematic paddle stay where they were loaded.
    for name in ("ramp", "paddle"):
        i = res.index(name)
        np.testing.assert_array_equal(
            data.transforms[:, i], np.tile(res.transforms()[i], (16, 1, 1))
        )


@needs_world
def test_real_world_kinematic_links_follow_the_joint_trajectory_exactly(tmp_path, data_dir):
    import pinocchio as pin

    res = load_urdf(data_dir / "arm.urdf", kinematic=True)
    world = res.make_world(dt=0.01)
    q = lambda t: np.array([np.sin(3 * t), 0.03 * np.cos(5 * t)])  # noqa: E731
    driver = RobotDriver(res, q)
    driver.attach(world)
    data = res.model.createData()
    for k in range(1, 21):
        world.step()
        pin.forwardKinematics(res.model, data, q(0.01 * k))
        T = world.transforms()
        for j, i in res.source_map.items():
            np.testing.assert_allclose(T[i], data.oMi[j].homogeneous, atol=1e-12)
    # ... and the same when logged with run_and_log and a driver applying targets.
    world2 = res.make_world(dt=0.01)
    run_and_log(world2, 10, tmp_path / "arm.mcap", driver=RobotDriver(res, q))
    log = read_log(tmp_path / "arm.mcap")
    for k in range(11):
        pin.forwardKinematics(res.model, data, q(0.01 * k) if k else res.q)
        np.testing.assert_allclose(log.transforms[k, 2], data.oMi[2].homogeneous, atol=1e-12)


@needs_world
def test_world_step_with_log_continues_one_file(tmp_path, scenes_dir):
    res = load_mjcf(scenes_dir / "free_bodies.xml")
    world = res.make_world()
    path = tmp_path / "steps.mcap"
    world.step(4, log=path)
    T4 = world.transforms()
    diag = world.step(3, log=str(path))
    assert diag.step == 6 and world.step_count == 7
    close_logs(world)
    data = read_log(path)
    assert not data.truncated and data.names == res.names
    np.testing.assert_array_equal(data.steps, np.arange(8))
    np.testing.assert_array_equal(data.transforms[4], T4)
    np.testing.assert_array_equal(data.transforms[-1], world.transforms())
    np.testing.assert_array_equal(data.diagnostics["step"], np.arange(7))
