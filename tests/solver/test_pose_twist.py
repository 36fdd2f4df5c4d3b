"""World.pose() / World.twist() against MuJoCo's qpos / qvel for tossed, spinning bodies.

MuJoCo's free joint stores ``qpos = [p, w, x, y, z]`` and ``qvel = [v (world), ω (body)]``;
abdsim's twist gives ω in the world frame, so ω_world = R qvel[3:6] is compared.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from abdsim.bridges import load_mjcf

SCENE = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "tossed_bodies.xml"
DT = 1e-3


def mujoco_state(model, data, name):
    j = model.joint(name).id
    qpos = data.qpos[model.jnt_qposadr[j] : model.jnt_qposadr[j] + 7]
    qvel = data.qvel[model.jnt_dofadr[j] : model.jnt_dofadr[j] + 6]
    R = data.xmat[model.body(name).id].reshape(3, 3)
    quat = qpos[3:] * np.sign(qpos[3])  # q and -q are one rotation; abdsim keeps w >= 0
    return qpos[:3], quat, qvel[:3], R @ qvel[3:]


def errors(world, names, model, data):
    p, q = world.pose()
    v, w = world.twist()
    out = []
    for i, name in enumerate(names):
        mp, mq, mv, mw = mujoco_state(model, data, name)
        out.append(
            [np.abs(x - y).max() for x, y in ((p[i], mp), (q[i], mq), (v[i], mv), (w[i], mw))]
        )
    return np.array(out)  # (bodies, [position, quaternion, linear, angular])


@pytest.fixture(scope="module")
def tossed():
    # The scene's solref has no abdsim counterpart; the loader says so rather than drop it.
    with pytest.warns(UserWarning, match="solref time constant"):
        res = load_mjcf(SCENE)
    world = res.make_world(dt=DT, integrator="bdf2")
    model = mujoco.MjModel.from_xml_path(str(SCENE))
    model.opt.timestep = DT
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    return res.names, world, model, data


def test_pose_and_twist_follow_mujoco_for_tossed_bodies(tossed):
    names, world, model, data = tossed
    assert len(names) == world.num_bodies == 7
    # Same state, same numbers: the conventions agree to rounding.
    assert errors(world, names, model, data).max() < 1e-14
    w = world.twist()[1]
    assert np.linalg.norm(w, axis=1).min() > 1.0  # every body spins
    for _ in range(300):  # 0.3 s of free flight, first contact is at 1.29 s
        world.step()
        mujoco.mj_step(model, data)
    err = errors(world, names, model, data)
    # BDF2 at h = 1e-3 against RK4: the tumbling T-bar is the hardest (Dzhanibekov).
    assert err[:, 0].max() < 2e-5  # position [m]
    assert err[:, 1].max() < 5e-4  # quaternion
    assert err[:, 2].max() < 1e-5  # linear velocity [m/s]
    assert err[:, 3].max() < 2e-3  # angular velocity [rad/s]
    # One body at a time returns that body's row.
    p3, q3 = world.pose(3)
    v3, w3 = world.twist(3)
    np.testing.assert_array_equal(p3, world.pose()[0][3])
    np.testing.assert_array_equal(q3, world.pose()[1][3])
    np.testing.assert_array_equal(w3, world.twist()[1][3])
    assert np.linalg.norm(q3) == pytest.approx(1.0, abs=1e-15) and q3[0] >= 0


def test_bad_body_index_names_the_range(tossed):
    _, world, _, _ = tossed
    for bad in (7, -1, 1.5, True):
        with pytest.raises(IndexError, match=r"body must be an integer index in \[0, 7\)"):
            world.pose(bad)
