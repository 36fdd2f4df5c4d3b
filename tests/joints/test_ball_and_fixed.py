"""Ball and fixed joints against Pinocchio (ABA + RK4 on the configuration manifold): a
spinning spherical pendulum, and a hinged link with a second link welded to its tip (one
rigid pendulum)."""

from __future__ import annotations

import numpy as np

import abdsim
from tests.joints.conftest import aba_rk4, link, pin_inertia, rot_y


def _skew(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def _quat_matrix(wxyz):
    w, x, y, z = wxyz
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def test_spherical_pendulum_matches_pinocchio():
    import pinocchio as pin

    axis = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    R0 = pin.exp3(0.5 * axis)
    omega = np.array([0.3, -0.5, 2.0])  # world angular velocity: swing and spin
    sc = link(kappa=1e10, extents=(0.2, 0.1, 1.0))
    T = np.eye(4)
    T[:3, :3] = R0
    sc.transforms = T[None]
    V = np.zeros((4, 4))
    V[:3, :3] = _skew(omega) @ R0  # Ȧ = [ω]× A; the origin (the joint) stays: ṗ = 0
    sc.instances["velocity"] = V[None]
    scene = abdsim.Scene(dt=1e-3, integrator="bdf2", contact=False)
    h = scene.add(sc)
    scene.add_joint("ball", None, h, anchor=(0, 0, 0), name="shoulder")
    world = abdsim.World(scene)
    np.testing.assert_allclose(world.joint_positions(), [1, 0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(world.joint_velocities(), R0.T @ omega, atol=1e-9)

    model = pin.Model()
    j = model.addJoint(0, pin.JointModelSpherical(), pin.SE3.Identity(), "ball")
    model.appendBodyToJoint(j, pin_inertia(sc), pin.SE3.Identity())
    q0 = pin.Quaternion(R0).coeffs()  # x, y, z, w
    qs, vs = aba_rk4(model, q0, R0.T @ omega, 0.8, 1e-4, 100, velocities=True)

    worst_R, worst_v, worst_gap = 0.0, 0.0, 0.0
    for k in range(1, len(qs)):
        world.step(10)
        quat = world.joint_positions()
        assert abs(np.linalg.norm(quat) - 1.0) < 1e-12
        R_ref = pin.Quaternion(qs[k]).matrix()
        worst_R = max(worst_R, np.abs(R0 @ _quat_matrix(quat) - R_ref).max())
        worst_v = max(worst_v, np.abs(world.joint_velocities() - vs[k]).max())
        worst_gap = max(worst_gap, world.diagnostics.joint_violation)
    assert worst_R < 1e-3, worst_R
    assert worst_v < 1e-2, worst_v
    assert worst_gap <= 1e-6
    assert np.abs(qs[-1] - q0).max() > 0.1  # it moved


def test_welded_link_moves_as_one_rigid_pendulum():
    import pinocchio as pin

    q1 = 0.7
    scene = abdsim.Scene(dt=1e-3, integrator="bdf2", contact=False)
    handles = []
    for k in range(2):
        sc = link(kappa=1e10, extents=(0.05, 0.05, 1.0) if k == 0 else (0.3, 0.1, 1.0))
        T = np.eye(4)
        T[:3, :3] = rot_y(q1)
        T[:3, 3] = rot_y(q1) @ np.array([0.0, 0.0, -1.0 * k])
        sc.transforms = T[None]
        handles.append(scene.add(sc))
    scene.add_joint("revolute", None, handles[0], anchor=(0, 0, 0), axis=(0, 1, 0))
    tip = rot_y(q1) @ np.array([0.0, 0.0, -1.0])
    scene.add_joint("fixed", handles[0], handles[1], anchor=tip, name="weld")
    world = abdsim.World(scene)
    assert world.joint_positions().shape == (1,)  # the weld has no coordinate

    model = pin.Model()
    j = model.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "hinge")
    model.appendBodyToJoint(j, pin_inertia(handles[0].sc), pin.SE3.Identity())
    model.appendBodyToJoint(
        j, pin_inertia(handles[1].sc), pin.SE3(np.eye(3), np.array([0.0, 0.0, -1.0]))
    )
    ref = aba_rk4(model, [q1], [0.0], 1.0, 1e-4, 100)
    worst, gaps = 0.0, np.zeros(2)
    for k in range(1, len(ref)):
        d = world.step(10)
        worst = max(worst, abs(world.joint_positions()[0] + q1 - ref[k, 0]))
        gaps = np.maximum(gaps, (d.joint_violation, d.joint_violation_angle))
    assert worst < 1e-3, worst
    assert gaps.max() <= 1e-6, gaps
    assert abs(ref[-1, 0] - q1) > 0.5
