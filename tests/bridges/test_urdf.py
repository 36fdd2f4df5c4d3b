"""URDF loading against Pinocchio: exact mass properties, poses, geometry, velocities, driver."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import trimesh

import abdsim
from abdsim.bridges import RobotDriver, load_urdf

ROBOTS = [
    ("panda_description", "panda.urdf"),
    ("ur_description", "ur5_robot.urdf"),
    ("double_pendulum_description", "double_pendulum.urdf"),
]


def random_q(model, seed=0):
    """A random configuration inside finite joint limits (pin.randomConfiguration)."""
    np.random.seed(seed)
    lo = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -np.pi)
    hi = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, np.pi)
    return pin.randomConfiguration(model, np.maximum(lo, -10), np.minimum(hi, 10))


@pytest.mark.parametrize("robot", ROBOTS, ids=[r[1] for r in ROBOTS])
def test_mass_properties_equal_pinocchio_inertias(robot, robot_urdf, rel_err):
    res = load_urdf(robot_urdf(*robot))
    model = res.model
    assert res.format == "urdf" and len(res.bodies) == len(res.source_map)
    for j, i in res.source_map.items():
        body, ref = res.bodies[i], model.inertias[j]
        rb = abdsim.to_rigid_body(body.geometry)
        if ref.mass == 0:  # only a fixed root may lack a mass; it then gets its surface's
            assert body.kind == "fixed"
            continue
        assert rel_err(rb.mass, ref.mass) < 1e-9, body.name
        assert rel_err(rb.mass_center, ref.lever) < 1e-9, body.name
        assert rel_err(rb.inertia, ref.inertia) < 1e-9, body.name


def test_bodies_follow_pinocchio_joints_and_fixed_links_merge(robot_urdf):
    res = load_urdf(robot_urdf("panda_description", "panda.urdf"))
    model = res.model
    # One body per joint with geometry; panda_link8 and panda_hand are fixed to joint 7.
    hand = res.bodies[res.index("panda_hand")]
    assert hand.name == "panda_link7" and hand.joint == "panda_joint7"
    assert set(hand.links) >= {"panda_link7", "panda_link8", "panda_hand"}
    assert hand.geoms == ("panda_link7_0", "panda_hand_0")
    assert [b.kind for b in res.bodies] == ["fixed"] + ["kinematic"] * 9
    assert int(res.bodies[0].geometry.instances["is_fixed"][0]) == 1
    for j, i in res.source_map.items():
        if j > 0:
            parent = res.bodies[i].parent
            assert parent == res.source_map[model.parents[j]]


@pytest.mark.parametrize("robot", ROBOTS, ids=[r[1] for r in ROBOTS])
def test_poses_and_world_vertices_equal_pinocchio_kinematics(robot, robot_urdf):
    path = robot_urdf(*robot)
    model, collision_model = pin.buildModelsFromUrdf(
        str(path),
        package_dirs=[str(p) for p in path.parents],
        geometry_types=[pin.GeometryType.COLLISION],
    )[:2]
    q = random_q(model, seed=3)
    res = load_urdf(path, q=q)
    data, cdata = model.createData(), collision_model.createData()
    pin.forwardKinematics(model, data, q)
    pin.updateGeometryPlacements(model, data, collision_model, cdata)
    for j, i in res.source_map.items():
        np.testing.assert_allclose(res.bodies[i].transform, data.oMi[j].homogeneous, atol=1e-12)
    for k, g in enumerate(collision_model.geometryObjects):
        body = res.bodies[res.source_map[g.parentJoint]]
        start, stop = body.geom_ranges[g.name]
        x_bar = body.geometry.positions[start:stop]
        world = x_bar @ body.transform[:3, :3].T + body.transform[:3, 3]
        oMg = cdata.oMg[k].homogeneous
        local = (world - oMg[:3, 3]) @ oMg[:3, :3]  # back into the geometry's own frame
        if g.meshPath and g.meshPath.endswith((".stl", ".STL", ".dae", ".obj")):
            mesh = trimesh.load(g.meshPath, force="mesh")
            ref = np.asarray(mesh.vertices) * np.asarray(g.meshScale)
            np.testing.assert_allclose(local, ref, atol=1e-12)
        else:  # a box: its vertices are the corners ±halfSide in the geometry's frame
            np.testing.assert_allclose(
                np.abs(local), np.broadcast_to(g.geometry.halfSide, local.shape), atol=1e-12
            )


def test_test_arm_primitives_mesh_and_merged_fixed_links(data_dir, rel_err):
    res = load_urdf(data_dir / "arm.urdf", q=[0.4, 0.02])
    model = res.model
    assert res.names == ["base", "arm", "finger"]
    arm = res.bodies[1]
    assert arm.links == ("arm", "tool", "marker") and arm.geoms == ("arm_0", "arm_1", "tool_0")
    assert res.bodies[2].parent == 1 and res.bodies[1].parent == 0
    # The merged arm + tool inertia, computed here from the URDF numbers by hand.
    R_arm = pin.rpy.rpyToMatrix(0.1, 0.2, 0.3)
    I_arm = R_arm @ np.array([[1e-3, 1e-4, 0], [1e-4, 4e-3, 0], [0, 0, 4e-3]]) @ R_arm.T
    R_mount = pin.rpy.rpyToMatrix(0.3, 0, 0)
    R_tool = R_mount @ pin.rpy.rpyToMatrix(0, 0.4, 0)
    I_tool = R_tool @ np.diag([2e-4, 2e-4, 1e-4]) @ R_tool.T
    c_arm, c_tool = np.array([0.1, 0, 0]), np.array([0.25, 0, 0]) + R_mount @ [0, 0, 0.02]
    m = 0.7
    c = (0.5 * c_arm + 0.2 * c_tool) / m
    inertia = sum(
        inertia_i + mi * ((ci - c) @ (ci - c) * np.eye(3) - np.outer(ci - c, ci - c))
        for mi, ci, inertia_i in ((0.5, c_arm, I_arm), (0.2, c_tool, I_tool))
    )
    rb = abdsim.to_rigid_body(arm.geometry)
    assert rel_err(rb.mass, m) < 1e-12
    assert rel_err(rb.mass_center, c) < 1e-9
    assert rel_err(rb.inertia, inertia) < 1e-9
    # The scaled STL in the arm frame: mount ∘ origin ∘ scale.
    start, stop = arm.geom_ranges["tool_0"]
    wedge = trimesh.load(data_dir / "meshes" / "wedge.stl", force="mesh")
    X = np.eye(4)
    X[:3, :3] = R_mount @ pin.rpy.rpyToMatrix(0.2, 0, 0)
    X[:3, 3] = [0.25, 0, 0] + R_mount @ [0, 0, 0.03]
    ref = (np.asarray(wedge.vertices) * [1, 2, 0.5]) @ X[:3, :3].T + X[:3, 3]
    np.testing.assert_allclose(arm.geometry.positions[start:stop], ref, atol=1e-12)
    # The sphere of the arm: every vertex at 0.03 from (0.2, 0, 0).
    s0, s1 = arm.geom_ranges["arm_1"]
    r = np.linalg.norm(arm.geometry.positions[s0:s1] - [0.2, 0, 0], axis=1)
    np.testing.assert_allclose(r, 0.03, rtol=1e-12)
    # The finger slides 2 cm along its joint's x axis.
    data = model.createData()
    pin.forwardKinematics(model, data, np.array([0.4, 0.02]))
    np.testing.assert_allclose(res.bodies[2].transform, data.oMi[2].homogeneous, atol=1e-14)


def test_initial_velocity_is_the_derivative_of_the_pose(data_dir):
    q = np.array([0.4, 0.01])
    v = np.array([1.5, -0.3])
    res = load_urdf(data_dir / "arm.urdf", q=q, v=v)
    model, h = res.model, 1e-6
    data = model.createData()
    for j, i in res.source_map.items():
        if j == 0:
            assert not res.bodies[i].velocity.any()
            continue
        pin.forwardKinematics(model, data, pin.integrate(model, q, v * h))
        T1 = data.oMi[j].homogeneous.copy()
        pin.forwardKinematics(model, data, pin.integrate(model, q, -v * h))
        T0 = data.oMi[j].homogeneous.copy()
        np.testing.assert_allclose(res.bodies[i].velocity, (T1 - T0) / (2 * h), atol=1e-8)


def test_floating_base_root_is_dynamic_with_its_velocity(data_dir, rel_err):
    model = pin.buildModelFromUrdf(str(data_dir / "arm.urdf"), pin.JointModelFreeFlyer())
    q = pin.neutral(model)
    q[:3] = [0.1, 0.2, 1.0]
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.3, -0.2, 0.9)).coeffs()
    q[7:] = [0.5, 0.0]
    v = np.zeros(model.nv)
    v[:6] = [0.3, -0.1, 0.2, 1.0, 2.0, -0.5]  # body frame (Pinocchio's free flyer)
    res = load_urdf(data_dir / "arm.urdf", q=q, v=v, floating_base=True)
    assert [b.kind for b in res.bodies] == ["dynamic", "kinematic", "kinematic"]
    base = res.bodies[0]
    assert int(base.geometry.instances["is_fixed"][0]) == 0
    R = pin.Quaternion(q[3:7]).toRotationMatrix()
    w = R @ v[3:6]
    np.testing.assert_allclose(base.transform[:3, :3], R, atol=1e-14)
    np.testing.assert_allclose(base.velocity[:3, 3], R @ v[:3], atol=1e-14)
    np.testing.assert_allclose(
        base.velocity[:3, :3], np.cross(w, R.T).T, atol=1e-14
    )  # Ȧ = [ω]× A, column by column
    assert rel_err(abdsim.to_rigid_body(base.geometry).mass, 2.0) < 1e-12


def test_robot_driver_follows_the_joint_trajectory_exactly(robot_urdf):
    res = load_urdf(robot_urdf("ur_description", "ur5_robot.urdf"))
    model = res.model
    data = model.createData()
    times = np.array([0.0, 0.5, 1.0, 2.0])
    samples = np.array([random_q(model, seed=s) for s in range(4)])
    driver = RobotDriver(res, samples, times=times)
    assert driver.bodies == res.indices("kinematic") == list(range(1, 7))
    for t, q in zip(times, samples, strict=True):  # at the samples: exactly FK(q_i)
        T, _ = driver.targets(t)
        pin.forwardKinematics(model, data, q)
        for k, i in enumerate(driver.bodies):
            j = next(j for j, b in res.source_map.items() if b == i)
            np.testing.assert_allclose(T[k], data.oMi[j].homogeneous, atol=1e-14)
    # Between samples: FK of Pinocchio's interpolation; velocity = its time derivative.
    t = 1.3
    q = pin.interpolate(model, samples[2], samples[3], 0.3)
    T, V = driver.targets(t)
    h = 1e-6
    Tp, _ = driver.targets(t + h)
    Tm, _ = driver.targets(t - h)
    pin.forwardKinematics(model, data, q)
    for k, i in enumerate(driver.bodies):
        j = next(j for j, b in res.source_map.items() if b == i)
        np.testing.assert_allclose(T[k], data.oMi[j].homogeneous, atol=1e-12)
        np.testing.assert_allclose(V[k], (Tp[k] - Tm[k]) / (2 * h), atol=1e-6)
    # Outside the samples the end configurations hold, at rest.
    T_end, V_end = driver.targets(5.0)
    np.testing.assert_allclose(T_end, driver.targets(2.0)[0], atol=0)
    assert not V_end.any()


def test_robot_driver_with_a_callable_trajectory(data_dir):
    res = load_urdf(data_dir / "arm.urdf")
    driver = RobotDriver(res, lambda t: np.array([np.sin(t), 0.01 * t]))
    T, V = driver.targets(0.7)
    data = res.model.createData()
    pin.forwardKinematics(
        res.model, data, np.array([np.sin(0.7), 0.007]), np.array([np.cos(0.7), 0.01])
    )
    for k, j in enumerate((1, 2)):
        np.testing.assert_allclose(T[k], data.oMi[j].homogeneous, atol=1e-14)
        R = data.oMi[j].rotation
        w, vlin = R @ data.v[j].angular, R @ data.v[j].linear
        np.testing.assert_allclose(V[k][:3, 3], vlin, atol=1e-8)
        np.testing.assert_allclose(V[k][:3, :3], np.cross(w, R.T).T, atol=1e-8)


def test_limbs_of_a_floating_base_follow_the_simulated_base(data_dir):
    res = load_urdf(data_dir / "arm.urdf", floating_base=True)
    q = pin.neutral(res.model)
    q[7] = 0.3
    driver = RobotDriver(res, q)
    with pytest.raises(ValueError, match="anchor_transforms"):
        driver.targets(0.0)
    moved = res.transforms()
    shift = np.eye(4)
    shift[:3, :3] = pin.rpy.rpyToMatrix(0.1, 0.2, 0.3)
    shift[:3, 3] = [1.0, -2.0, 0.5]
    moved[0] = shift @ moved[0]
    T, _ = driver.targets(0.0, anchor_transforms=moved)
    data = res.model.createData()
    pin.forwardKinematics(res.model, data, q)
    for k, j in enumerate((2, 3)):
        np.testing.assert_allclose(T[k], shift @ data.oMi[j].homogeneous, atol=1e-13)


def test_joint_info_in_world_frame(data_dir):
    q = np.array([0.4, 0.02])
    res = load_urdf(data_dir / "arm.urdf", q=q)
    data = res.model.createData()
    pin.forwardKinematics(res.model, data, q)
    shoulder, slide = res.joints
    assert (shoulder.name, shoulder.type, shoulder.parent, shoulder.child) == (
        "shoulder",
        "revolute",
        0,
        1,
    )
    np.testing.assert_allclose(shoulder.anchor, data.oMi[1].translation, atol=1e-15)
    np.testing.assert_allclose(shoulder.axis, data.oMi[1].rotation[:, 1], atol=1e-15)  # URDF y
    assert (slide.type, slide.parent, slide.child) == ("prismatic", 1, 2)
    np.testing.assert_allclose(slide.axis, data.oMi[2].rotation[:, 0], atol=1e-15)  # URDF x
    assert load_urdf(data_dir / "arm.urdf", floating_base=True).joints[0].type == "free"


def test_robot_driver_without_pinocchio_data_matches_forward_kinematics(robot_urdf, monkeypatch):
    """Large trees skip pinocchio.Data (cubic in the joint count); the one-pass kinematics
    they use instead gives Pinocchio's poses and velocities (UR5, forced onto that path)."""
    import abdsim.bridges.drivers as drivers

    res = load_urdf(robot_urdf("ur_description", "ur5_robot.urdf"))
    samples = np.array([random_q(res.model, seed=s) for s in range(2)])
    with_data = RobotDriver(res, samples, times=[0.0, 1.0])
    monkeypatch.setattr(drivers, "_DATA_MAX_NV", 0)
    without = RobotDriver(res, samples, times=[0.0, 1.0])
    assert without._data is None and with_data._data is not None
    for t in (0.0, 0.37, 1.0):
        T0, V0 = with_data.targets(t)
        T1, V1 = without.targets(t)
        np.testing.assert_allclose(T1, T0, atol=1e-14)
        np.testing.assert_allclose(V1, V0, atol=1e-12)
