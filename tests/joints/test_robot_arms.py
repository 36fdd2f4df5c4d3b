"""example-robot-data's UR5 and Panda (fixed base, zero torque, released from a
non-singular pose) as abdsim articulations against Pinocchio's ABA + RK4: link positions
over 0.5 s."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from abdsim.bridges.pinocchio_articulation import articulation_from_pinocchio
from tests.joints.conftest import aba_rk4, robot_model


@pytest.mark.parametrize(
    "description, filename, tolerance",
    [("ur_description", "ur5_robot.urdf", 2e-3), ("panda_description", "panda.urdf", 2e-3)],
)
def test_arm_falls_like_pinocchio(description, filename, tolerance):
    import pinocchio as pin

    model = robot_model(description, filename)
    if model is None:
        pytest.skip(f"example-robot-data's {filename} is not installed")
    q0 = pin.neutral(model) + 0.3 * np.sin(np.arange(model.nq) + 1.0)  # non-singular
    # Default Newton tolerances: jointed bodies start from last step's solution of the
    # joint forces (World's warm start), so the first direction is already within them.
    scene = abdsim.Scene(dt=1e-3, integrator="bdf2", contact=False)
    bodies = articulation_from_pinocchio(model, q0, scene)
    world = abdsim.World(scene)
    ref = aba_rk4(model, q0, np.zeros(model.nv), 0.5, 1e-4, 100)  # every 0.01 s
    data = model.createData()
    worst, violation, iterations = 0.0, 0.0, 0
    for k in range(1, 501):
        d = world.step()
        violation = max(violation, d.joint_violation, d.joint_violation_angle)
        iterations += d.newton_iterations
        if k % 10 == 0:
            pin.forwardKinematics(model, data, ref[k // 10])
            for i in range(1, model.njoints):
                gap = world.q[bodies[i].start][:3] - data.oMi[i].translation
                worst = max(worst, float(np.linalg.norm(gap)))
    assert worst < tolerance, worst  # measured: UR5 0.20 mm, Panda 0.17 mm
    assert violation <= 1e-6, violation
    # The warm start leaves one Newton iteration per step (measured 1.00 on both; 2.2-2.3
    # when Newton started from q_t).
    assert iterations / 500 <= 1.2, iterations / 500
    assert np.abs(ref[-1] - q0).max() > 0.5  # the arm really fell
