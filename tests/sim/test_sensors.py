"""Sensors added from Python (World.add_sensor / Scene.sensors) against closed forms: touch
zones, the force and torque a kinematic support carries, accelerometers at rest and in free
fall (BDF1, BDF2), gyro and velocimeter of a spinning body, relative frames, the layout, and
bad input."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import abdsim

G = 9.81


def box(extents, pos, density=1e3):
    sc = abdsim.geometry.from_trimesh(trimesh.creation.box(extents=extents))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8, mass_density=density)
    T = np.eye(4)
    T[:3, 3] = pos
    sc.transforms = T[None]
    return sc


def rot_quat(axis, angle):
    """(R, quaternion w-first) of a rotation about an axis."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    R = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    return R, np.array([np.cos(angle / 2), *(np.sin(angle / 2) * axis)])


def read(world, i):
    a, k = world.sensor_adr[i], world.sensor_dim[i]
    return world.sensordata[a : a + k]


def resting_box_world(**settings):
    scene = abdsim.Scene(dt=0.01, **settings)
    scene.add_ground(0.0)
    scene.add(box((0.2, 0.1, 0.1), (0.0, 0.0, 0.0505)))  # 2 kg
    return scene


def test_touch_zone_counts_the_contacts_inside_it():
    """A 2 kg box at rest: a zone around its whole sole reads m g, one around the two
    corners at x > 0 reads half of it (by symmetry), one above the box nothing (1e-6)."""
    scene = resting_box_world()
    whole = scene.sensors.add("touch", 0, (0, 0, -0.05), zone="box", size=(0.12, 0.07, 0.01))
    world = abdsim.World(scene)
    half = world.add_sensor("touch", 0, (0.1, 0, -0.05), zone="sphere", size=0.02 * 2**0.5 + 0.06)
    none = world.add_sensor("touch", 0, (0, 0, 0.05), zone="cylinder", size=(0.3, 0.01))
    world.step(100)
    assert read(world, whole)[0] == pytest.approx(2 * G, rel=1e-6)
    assert read(world, half)[0] == pytest.approx(G, rel=1e-6)
    assert read(world, none)[0] == 0.0


def test_kinematic_support_force_and_torque_are_what_it_carries():
    """A scripted (kinematic, still) plate carries a 1 kg box 5 cm off its centre: the force
    sensor at the plate's centre reads (m_plate + m_box) g up, the torque sensor the box's
    weight times its centre's offset (≈ 5 cm) about −y, within 1e-6 and 1e-5 (the Newton
    tolerance's residual; the sensor is what the script applies)."""
    scene = abdsim.Scene(dt=0.01, newton_tol_translation=1e-7, newton_tol_affine=1e-6)
    plate = box((0.4, 0.3, 0.02), (0.0, 0.0, 0.0))  # 2.4 kg
    scene.add(plate, kinematic=True)
    scene.add(box((0.1, 0.1, 0.1), (0.05, 0.0, 0.0605)))  # 1 kg, 0.5 mm above
    world = abdsim.World(scene)
    force = world.add_sensor("force", 0)
    torque = world.add_sensor("torque", 0)
    world.step(100)
    m_plate, m_box = 2.4, 1.0
    weight = (m_plate + m_box) * G
    np.testing.assert_allclose(read(world, force), [0, 0, weight], rtol=1e-6, atol=1e-6 * weight)
    # At rest the box's weight acts under its centre (x, y), which landing moved by ~1e-5 m.
    x, y = world.transforms()[1, :2, 3]
    assert abs(x - 0.05) < 1e-4 and np.abs(world.q_dot[1]).max() < 1e-6
    np.testing.assert_allclose(
        read(world, torque), [y * m_box * G, -x * m_box * G, 0], atol=1e-5 * m_box * G * 0.05
    )


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_accelerometer_reads_plus_g_at_rest_and_zero_in_free_fall(integrator):
    """In a rotated site frame: R̄ᵀ (0, 0, g) on the resting box (1e-6), 0 on a falling one
    (1e-9: free fall's step acceleration is exactly g)."""
    scene = resting_box_world(integrator=integrator)
    scene.add(box((0.1, 0.1, 0.1), (1.0, 0.0, 50.0)))
    R, quat = rot_quat([1, 2, 3], 0.7)
    world = abdsim.World(scene)
    rest = world.add_sensor("accelerometer", 0, (0.05, 0.02, 0.0), quat)
    fall = world.add_sensor("accelerometer", 1, (0.05, 0.02, 0.0), quat)
    assert not read(world, rest).any()  # no step yet
    world.step(100)
    np.testing.assert_allclose(read(world, rest), R.T @ [0, 0, G], atol=1e-6)
    np.testing.assert_allclose(read(world, fall), 0.0, atol=1e-9)
    world.set_state()  # a new state: no step since
    assert not read(world, rest).any()


def test_gyro_velocimeter_and_relative_frames_of_a_spinning_body():
    """A cube spinning about z without gravity (BDF1). Over the last step: the velocimeter
    of an offset, tilted site reads its displacement / h in its frame (1e-9: BDF1's velocity
    is exactly that), the gyro the rotation vector of R_{t+1} R_tᵀ / h (scipy; 1e-4
    relative: chord vs arc); framepos / framequat relative to a second body are its frame from
    the transforms (1e-9)."""
    from scipy.spatial.transform import Rotation

    scene = abdsim.Scene(dt=0.01, gravity=(0, 0, 0), contact=False)
    cube = box((0.1, 0.1, 0.1), (0.0, 0.0, 0.0))
    cube.instances["velocity"][0][:3, :3] = [[0, -2, 0], [2, 0, 0], [0, 0, 0]]
    cube.instances["velocity"][0][:3, 3] = [0.1, 0.0, 0.3]
    scene.add(cube)
    R_ref, _ = rot_quat([0, 1, 0], 0.4)
    other = box((0.1, 0.1, 0.1), (1.0, 2.0, 3.0))
    T = np.array(other.transforms)
    T[0, :3, :3] = R_ref
    other.transforms = T
    scene.add(other)
    R, quat = rot_quat([1, 0, 1], 0.5)
    r = np.array([0.05, 0.01, -0.02])
    world = abdsim.World(scene)
    gyro = world.add_sensor("gyro", 0, r, quat)
    vel = world.add_sensor("velocimeter", 0, r, quat)
    pos = world.add_sensor("framepos", 0, r, quat, ref=1)
    frame_quat = world.add_sensor("framequat", 0, r, quat, ref=1)

    def site_pose():
        T = world.transforms()[0]
        U, _, Wt = np.linalg.svd(T[:3, :3])
        return T[:3, :3] @ r + T[:3, 3], U @ Wt @ R  # site origin and frame in the world

    world.step(49)
    x0, S0 = site_pose()
    world.step()
    x1, S1 = site_pose()
    np.testing.assert_allclose(read(world, vel), S1.T @ (x1 - x0) / 0.01, atol=1e-9)
    omega = Rotation.from_matrix(S1 @ S0.T).as_rotvec() / 0.01
    assert abs(omega[2]) > 1.9 and np.abs(omega[:2]).max() < 1e-9
    np.testing.assert_allclose(read(world, gyro), S1.T @ omega, rtol=1e-4)
    np.testing.assert_allclose(read(world, pos), R_ref.T @ (x1 - [1.0, 2.0, 3.0]), atol=1e-9)
    w, qx, qy, qz = read(world, frame_quat)
    Rq = Rotation.from_quat([qx, qy, qz, w]).as_matrix()
    np.testing.assert_allclose(Rq, R_ref.T @ S1, atol=1e-9)


def test_layout_cutoff_and_bad_input():
    """sensor_adr / sensor_dim follow the order of addition; cutoff clamps; bad input is a
    ValueError naming the sensor and leaves the set as it was."""
    scene = resting_box_world()
    world = abdsim.World(scene)
    world.add_sensor("framequat", 0, name="q")
    world.add_sensor("touch", 0, (0, 0, -0.05), name="sole", zone="box", size=(1, 1, 0.1), cutoff=5)
    world.add_sensor("gyro", 0, name="w")
    np.testing.assert_array_equal(world.sensor_adr, [0, 4, 5])
    np.testing.assert_array_equal(world.sensor_dim, [4, 1, 3])
    assert world.sensor_names == ["q", "sole", "w"]
    world.step(50)
    assert read(world, 1)[0] == 5.0  # m g = 19.6 N, cut off at 5
    with pytest.raises(ValueError, match="sensor type"):
        world.add_sensor("lidar", 0)
    with pytest.raises(ValueError, match="'t' \\(touch\\).*size"):
        world.add_sensor("touch", 0, name="t")
    with pytest.raises(ValueError, match="out of range"):
        world.add_sensor("gyro", 7)
    with pytest.raises(ValueError, match="reference frame"):
        world.add_sensor("gyro", 0, ref=0)
    with pytest.raises(ValueError, match="finite"):
        world.add_sensor("gyro", 0, (np.nan, 0, 0))
    assert len(world.sensors) == 3 and len(world.sensordata) == 8
