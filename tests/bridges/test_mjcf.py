"""MJCF loading against MuJoCo: exact mass properties, geometry, poses, velocities, driver."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest
import trimesh

import abdsim
from abdsim.bridges import MjcfDriver, load_mjcf


def quat2mat(q):
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, np.asarray(q, dtype=np.float64))
    return R.reshape(3, 3)


def reference(path, keyframe=True):
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    if keyframe and m.nkey:
        mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    return m, d


def body_pose(d, b):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = d.xmat[b].reshape(3, 3), d.xpos[b]
    return T


@pytest.fixture
def scene(scenes_dir):
    path = scenes_dir / "free_bodies.xml"
    return path, load_mjcf(path, kinematic=True), *reference(path)


def test_bodies_kinds_settings_and_ground(scene):
    path, res, m, _ = scene
    assert res.names == ["ramp", "box", "ball", "pill", "can", "egg", "gem", "dumbbell", "paddle"]
    assert [b.kind for b in res.bodies] == ["fixed"] + ["dynamic"] * 7 + ["kinematic"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        articulated = load_mjcf(path)  # the default: the hinged paddle is dynamic
    assert [b.kind for b in articulated.bodies] == ["fixed"] + ["dynamic"] * 8
    assert articulated.joint_names == [j.name for j in articulated.scene.joints]
    assert res.dt == m.opt.timestep == 0.01
    np.testing.assert_array_equal(res.gravity, [0, 0, -9.81])
    (ground,) = res.grounds
    assert (ground.name, ground.height, ground.friction) == ("floor", 0.0, 0.8)
    np.testing.assert_array_equal(ground.normal, [0, 0, 1])
    assert res.bodies[res.index("ball")].friction == 0.6
    assert res.bodies[res.index("blade")].name == "paddle"  # a geom name finds its body
    assert res.bodies[-1].links == ("paddle", "paddle_blade")
    assert int(res.bodies[0].geometry.instances["is_fixed"][0]) == 1
    assert not any(int(b.geometry.instances["is_fixed"][0]) for b in res.bodies[1:])


def test_mass_properties_equal_mujoco(scene, rel_err):
    _, res, m, d = scene
    for b, i in res.source_map.items():
        rb = abdsim.to_rigid_body(res.bodies[i].geometry)
        if res.bodies[i].links == (m.body(b).name,):  # a single MuJoCo body: its own numbers
            R = quat2mat(m.body_iquat[b])
            inertia = R @ np.diag(m.body_inertia[b]) @ R.T
            assert rel_err(rb.mass, m.body_mass[b]) < 1e-9
            assert rel_err(rb.mass_center, m.body_ipos[b]) < 1e-9
            assert rel_err(rb.inertia, inertia) < 1e-9
    # The paddle and its welded blade: combine MuJoCo's world-frame inertias, then express
    # them in the paddle's frame.
    paddle, blade = m.body("paddle").id, m.body("paddle_blade").id
    masses = m.body_mass[[paddle, blade]]
    coms = d.xipos[[paddle, blade]]
    c = masses @ coms / masses.sum()
    inertia_w = np.zeros((3, 3))
    for b, mass, com in zip((paddle, blade), masses, coms, strict=True):
        Rb = d.ximat[b].reshape(3, 3)
        r = com - c
        inertia_w += Rb @ np.diag(m.body_inertia[b]) @ Rb.T + mass * (
            r @ r * np.eye(3) - np.outer(r, r)
        )
    T = body_pose(d, paddle)
    rb = abdsim.to_rigid_body(res.bodies[res.index("paddle")].geometry)
    assert rel_err(rb.mass, masses.sum()) < 1e-12
    assert rel_err(rb.mass_center, T[:3, :3].T @ (c - T[:3, 3])) < 1e-9
    assert rel_err(rb.inertia, T[:3, :3].T @ inertia_w @ T[:3, :3]) < 1e-9


def test_world_vertices_equal_mujoco_geoms(scene):
    _, res, m, d = scene
    checked = 0
    for body in res.bodies:
        T = body.transform
        for name, (start, stop) in body.geom_ranges.items():
            g = m.geom(name).id
            world = body.geometry.positions[start:stop] @ T[:3, :3].T + T[:3, 3]
            R, x = d.geom_xmat[g].reshape(3, 3), d.geom_xpos[g]
            local = (world - x) @ R  # in the geom's frame
            size = m.geom_size[g]
            kind = mujoco.mjtGeom(m.geom_type[g])
            if kind == mujoco.mjtGeom.mjGEOM_MESH:
                a, n = m.mesh_vertadr[m.geom_dataid[g]], m.mesh_vertnum[m.geom_dataid[g]]
                np.testing.assert_allclose(world, m.mesh_vert[a : a + n] @ R.T + x, atol=1e-12)
            elif kind == mujoco.mjtGeom.mjGEOM_BOX:
                np.testing.assert_allclose(
                    np.abs(local), np.broadcast_to(size, local.shape), atol=1e-12
                )
            elif kind == mujoco.mjtGeom.mjGEOM_SPHERE:
                np.testing.assert_allclose(np.linalg.norm(local, axis=1), size[0], rtol=1e-12)
            elif kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
                np.testing.assert_allclose(np.sum((local / size) ** 2, axis=1), 1.0, rtol=1e-12)
            elif kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
                z = np.clip(local[:, 2], -size[1], size[1])
                dist = np.linalg.norm(local - np.c_[0 * z, 0 * z, z], axis=1)
                np.testing.assert_allclose(dist, size[0], rtol=1e-12)
            elif kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
                np.testing.assert_allclose(np.abs(local[:, 2]).max(), size[1], rtol=1e-12)
                np.testing.assert_allclose(
                    np.linalg.norm(local[:, :2], axis=1).max(), size[0], rtol=1e-12
                )
                assert np.all(np.linalg.norm(local[:, :2], axis=1) <= size[0] * (1 + 1e-12))
            checked += 1
    assert checked == 12  # every non-plane geom of the scene


def test_poses_and_keyframe_velocities(scene):
    _, res, m, d = scene
    for b, i in res.source_map.items():
        np.testing.assert_allclose(res.bodies[i].transform, body_pose(d, b), atol=1e-15)
    # A free joint: qvel = [v_world, ω_body] -> ṗ = v, Ȧ = [R ω_body]× R.
    for name in ("box", "pill", "egg", "dumbbell"):
        b = m.body(name).id
        dof = m.jnt_dofadr[m.body_jntadr[b]]
        v, w_body = d.qvel[dof : dof + 3], d.qvel[dof + 3 : dof + 6]
        R = d.xmat[b].reshape(3, 3)
        w = R @ w_body
        V = res.bodies[res.index(name)].velocity
        np.testing.assert_allclose(V[:3, 3], v, atol=1e-14)
        np.testing.assert_allclose(V[:3, :3], np.cross(w, R.T).T, atol=1e-14)
    # The hinged paddle: dT/dt by finite differences of MuJoCo's kinematics.
    h, b = 1e-6, m.body("paddle").id
    poses = []
    for sign in (1, -1):
        d2 = mujoco.MjData(m)
        d2.qpos[:] = d.qpos
        mujoco.mj_integratePos(m, d2.qpos, d.qvel, sign * h)
        mujoco.mj_kinematics(m, d2)
        poses.append(body_pose(d2, b))
    V = res.bodies[res.index("paddle")].velocity
    np.testing.assert_allclose(V, (poses[0] - poses[1]) / (2 * h), atol=1e-8)
    assert abs(V).max() > 0.1


def test_without_keyframe_bodies_start_at_qpos0_at_rest(scenes_dir):
    path = scenes_dir / "free_bodies.xml"
    res = load_mjcf(path, keyframe=None)
    m, d = reference(path, keyframe=False)
    for b, i in res.source_map.items():
        np.testing.assert_allclose(res.bodies[i].transform, body_pose(d, b), atol=1e-15)
        assert not res.bodies[i].velocity.any()


def test_mesh_file_recentred_by_mujoco_comes_back_in_the_body_frame(tmp_path):
    mesh = trimesh.creation.box((0.2, 0.1, 0.05))
    mesh.apply_transform(trimesh.transformations.rotation_matrix(0.4, [1, 2, 3]))
    mesh.apply_translation([0.3, -0.1, 0.05])  # far off its centre: MuJoCo re-centres it
    mesh.export(tmp_path / "block.stl")
    (tmp_path / "scene.xml").write_text(
        """<mujoco><asset><mesh name="block" file="block.stl"/></asset><worldbody>
        <body name="b" pos="0 0 1" euler="0 0 30"><freejoint/>
        <geom name="g" type="mesh" mesh="block" pos="0.05 0 0" euler="10 0 0"/></body>
        </worldbody></mujoco>"""
    )
    res = load_mjcf(tmp_path / "scene.xml")
    m, _ = reference(tmp_path / "scene.xml")
    assert np.abs(m.mesh_vert).max() < 0.13  # MuJoCo moved it
    X = np.eye(4)
    X[:3, :3] = quat2mat([np.cos(np.radians(5)), np.sin(np.radians(5)), 0, 0])
    X[:3, 3] = [0.05, 0, 0]
    expected = np.asarray(mesh.vertices) @ X[:3, :3].T + X[:3, 3]
    got = res.bodies[0].geometry.positions
    # Same point set (MuJoCo stores mesh vertices as float32).
    dist = np.linalg.norm(got[:, None] - expected[None], axis=2)
    assert dist.min(axis=1).max() < 1e-6 and dist.min(axis=0).max() < 1e-6


def test_visual_geoms_are_skipped_unless_asked(tmp_path):
    (tmp_path / "v.xml").write_text(
        """<mujoco><worldbody><body name="b"><freejoint/>
        <geom name="hit" type="sphere" size="0.1"/>
        <geom name="look" type="box" size="0.2 0.2 0.2" contype="0" conaffinity="0" mass="0"/>
        </body></worldbody></mujoco>"""
    )
    assert load_mjcf(tmp_path / "v.xml").bodies[0].geoms == ("hit",)
    assert load_mjcf(tmp_path / "v.xml", include_visual=True).bodies[0].geoms == ("hit", "look")


def test_mjcf_driver_moves_the_paddle_along_its_hinge(scene):
    _, res, m, _ = scene
    q0 = np.array(res.q)
    q1 = q0.copy()
    q1[-1] = -1.2
    driver = MjcfDriver(res, [q0, q1], times=[0.0, 2.0])
    assert driver.bodies == [res.index("paddle")]
    d = mujoco.MjData(m)
    for t in (0.0, 0.5, 2.0):
        d.qpos[:] = q0
        d.qpos[-1] = q0[-1] + (q1[-1] - q0[-1]) * t / 2.0
        mujoco.mj_kinematics(m, d)
        T, V = driver.targets(t)
        np.testing.assert_allclose(T[0], body_pose(d, m.body("paddle").id), atol=1e-14)
    # Rotation about the hinge axis (world y) at the rate (q1 - q0) / 2.
    T, V = driver.targets(1.0)
    rate = (q1[-1] - q0[-1]) / 2.0
    R = T[0][:3, :3]
    np.testing.assert_allclose(V[0][:3, :3], np.cross([0, rate, 0], R.T).T, atol=1e-12)
    np.testing.assert_allclose(V[0][:3, 3], 0, atol=1e-12)  # the hinge is at the body origin


def test_the_bundled_validation_scene_loads(scenes_dir, rel_err):
    path = scenes_dir / "tossed_bodies.xml"
    if not path.exists():
        pytest.skip("no tossed_bodies.xml")
    res = load_mjcf(path)
    m, _ = reference(path)
    assert res.indices("dynamic") == list(range(len(res.bodies)))
    for b, i in res.source_map.items():
        rb = abdsim.to_rigid_body(res.bodies[i].geometry)
        assert rel_err(rb.mass, m.body_mass[b]) < 1e-9


def test_joint_info_in_world_frame(scene):
    _, res, m, d = scene
    by_name = {j.name: j for j in res.joints}
    hinge = by_name["paddle_hinge"]
    assert (hinge.type, hinge.parent, hinge.child) == ("revolute", None, res.index("paddle"))
    np.testing.assert_allclose(hinge.anchor, [-1.0, 0.0, 0.3], atol=1e-15)
    np.testing.assert_allclose(hinge.axis, [0.0, 1.0, 0.0], atol=1e-15)
    assert by_name["box_free"].type == "free" and by_name["box_free"].axis is None
    assert sorted(j.child for j in res.joints) == list(range(1, 9))
