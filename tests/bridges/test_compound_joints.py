"""Bodies moved by several MJCF joints load as chains of joint frames (bridges/_joint_frames.py)
and move like MuJoCo: a planar root (cheetah's rootx, rootz, rooty) and three-hinge hips
(humanoid) against MuJoCo RK4, point_mass's two slides against the closed form, and a keyframe
chain (slide + two offset hinges, hinge + ball) placed and mapped exactly."""

from __future__ import annotations

import numpy as np
import pytest

from abdsim.bridges._joint_frames import FRAME_MASS_FRACTION
from abdsim.constitution.rigid_body import to_rigid_body

from .conftest import load_mjcf_quietly, suite_xml, worst_qpos_error

mujoco = pytest.importorskip("mujoco")

DT = 1e-3


def _against_mujoco_rk4(result, q0, v0, seconds: float) -> tuple[float, float, float]:
    """Both simulators from (q0, v0), zero control, no contact, dt = 1e-3: the largest hinge
    error (rad), slide error (m) and hinge excursion (rad) over ``seconds``. MuJoCo must stay
    clear of its joint limits (its soft limits and abdsim's barrier are different models)."""
    world = result.make_world(integrator="bdf2", contact=False, dt=DT)
    result.set_world_state(world, q0, v0)
    model = result.model
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.timestep = DT
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = q0, v0
    assert np.allclose(result.qpos_from_world(world), q0, atol=1e-12)
    assert np.allclose(result.qvel_from_world(world), v0, atol=1e-9)
    kind = np.asarray(model.jnt_type)
    adr = np.asarray(model.jnt_qposadr)
    hinges = adr[kind == int(mujoco.mjtJoint.mjJNT_HINGE)]
    slides = adr[kind == int(mujoco.mjtJoint.mjJNT_SLIDE)]
    hinge_err = slide_err = moved = 0.0
    for _ in range(round(seconds / DT)):
        world.step()
        mujoco.mj_step(model, data)
        assert data.nefc == 0, "MuJoCo reached a joint limit: choose another state"
        q = result.qpos_from_world(world)
        hinge_err = max(hinge_err, np.abs(q[hinges] - data.qpos[hinges]).max())
        if slides.size:
            slide_err = max(slide_err, np.abs(q[slides] - data.qpos[slides]).max())
        moved = max(moved, np.abs(data.qpos[hinges] - q0[hinges]).max())
    assert max(world.joint_violation()) <= 1e-9
    return hinge_err, slide_err, moved


def test_cheetah_planar_root_matches_mujoco_rk4():
    """cheetah's torso on rootx (slide), rootz (slide), rooty (hinge): from its spring
    reference with random joint and root velocities, 1 s falling freely (the file's springs,
    damping and masses): every hinge within 1e-4 rad of MuJoCo RK4 (measured 6.3e-6, the same
    with frames at 1e-3 of the mass) and the root slides within 1e-4 m (7.5e-6), while the
    hinges swing up to 0.26 rad."""
    result = load_mjcf_quietly(suite_xml("cheetah.xml"))
    assert result.joint_names[:3] == ["rootx", "rootz", "rooty"]
    model = result.model
    rng = np.random.default_rng(0)
    q0 = np.array(model.qpos0)
    v0 = 0.3 * rng.uniform(-1.0, 1.0, model.nv)
    hinge, slide, moved = _against_mujoco_rk4(result, q0, v0, 1.0)
    assert moved > 0.2
    assert hinge < 1e-4, hinge
    assert slide < 1e-4, slide


def test_humanoid_multi_hinge_hips_match_mujoco_rk4():
    """humanoid: a free root, two- and three-hinge abdomen, hips and ankles. Hinges part-way to
    their range's middle (knees bent to -1.2 rad), random velocities, 0.5 s: every hinge within
    1e-3 rad of MuJoCo RK4 (measured 5.9e-5 with joint frames at 1e-4 of the mass; 2.2e-4 at
    1e-3, 2.1e-3 at 1e-2) while they swing up to 1.1 rad."""
    result = load_mjcf_quietly(suite_xml("humanoid.xml"))
    model = result.model
    rng = np.random.default_rng(0)
    q0, v0 = np.array(model.qpos0), np.zeros(model.nv)
    v0[:6] = rng.uniform(-1.0, 1.0, 6)
    for j in range(1, model.njnt):
        lo, hi = model.jnt_range[j]
        name = model.joint(j).name
        q0[model.jnt_qposadr[j]] = -1.2 if "knee" in name else 0.3 * (lo + hi) / 2
        v0[model.jnt_dofadr[j]] = 0.5 * rng.uniform(-1.0, 1.0)
    hinge, _, moved = _against_mujoco_rk4(result, q0, v0, 0.5)
    assert moved > 1.0
    assert hinge < 1e-3, hinge


def test_point_mass_slides_follow_the_closed_form():
    """point_mass: root_x then root_y (slides, damping b = 1, m = 0.3 kg) driven by constant
    motors through one-joint fixed tendons (F = 0.1 u). From rest, x(t) = (F/b) t − (F m/b²)
    (1 − exp(−b t/m)) per axis. root_x moves the whole mass (frame and body): within 5e-7 m
    over 1 s (measured 1.7e-7: BDF2 at dt = 1e-3, 4.3e-8 at 5e-4); root_y moves the body only,
    which lacks the frame's share ε = FRAME_MASS_FRACTION of m: within that share's cost
    ε |F| m/b² (1.2e-6 m at ε = 1e-4; measured 1.0e-6, and 9.7e-8 at ε = 1e-6) plus the same
    5e-7. MuJoCo RK4 agrees with the closed form to 1e-7."""
    result = load_mjcf_quietly(suite_xml("point_mass.xml"))
    assert result.joint_names == ["root_x", "root_y"]
    assert result.actuator_names == ["t1", "t2"]
    world = result.make_world(integrator="bdf2", contact=False, dt=DT)
    model = result.model
    data = mujoco.MjData(model)
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.timestep = DT
    u = np.array([0.7, -0.4])
    world.ctrl[:] = data.ctrl[:] = u
    m = float(model.body_mass[model.body("pointmass").id])
    b = float(model.dof_damping[0])
    force = float(model.actuator_gear[0, 0]) * u
    assert (m, b) == (pytest.approx(0.3), 1.0)
    worst, mj_worst = np.zeros(2), 0.0
    for k in range(1, 1001):
        world.step()
        mujoco.mj_step(model, data)
        t = k * DT
        exact = force / b * t - force * m / b**2 * (1.0 - np.exp(-b * t / m))
        worst = np.maximum(worst, np.abs(world.joint_positions() - exact))
        mj_worst = max(mj_worst, np.abs(data.qpos - exact).max())
    assert np.abs(world.joint_positions()).min() > 0.025  # it moved 3-5 cm
    assert mj_worst < 1e-7, mj_worst
    assert worst[0] < 5e-7, worst
    assert worst[1] < FRAME_MASS_FRACTION * abs(force[1]) * m / b**2 + 5e-7, worst


_CHAIN = """<mujoco><compiler angle="radian"/><option timestep="1e-3" gravity="0 0 -9.81"/>
  <worldbody>
    <body name="base" pos="0 0 1">
      <joint name="slide_x" type="slide" axis="1 0 0" damping="0.3"/>
      <joint name="yaw" type="hinge" axis="0 0 1" pos="0.05 0 0" damping="0.1" armature="0.02"/>
      <joint name="pitch" type="hinge" axis="0 1 0" pos="0 0.03 0.02" stiffness="2"
             springref="0.1" range="-1 1" limited="true"/>
      <geom type="box" size="0.1 0.05 0.03" mass="1"/>
      <body name="link" pos="0.25 0 0">
        <joint name="roll" type="hinge" axis="1 0 0" pos="-0.05 0 0"/>
        <joint name="ball" type="ball" pos="0 0.1 0"/>
        <geom type="box" size="0.1 0.06 0.06" pos="0.05 0 0" mass="0.5"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="m_yaw" joint="yaw" gear="2"/>
    <position name="p_pitch" joint="pitch" kp="5"/>
  </actuator>
  <sensor>
    <jointpos name="s_pitch" joint="pitch"/>
    <jointvel name="s_yaw" joint="yaw"/>
  </sensor>
  <keyframe>
    <key qpos="0.1 0.4 -0.3 0.2 0.9238795 0 0.3826834 0" qvel="0.2 0.5 -0.4 0.6 0.3 -0.2 0.1"/>
  </keyframe>
</mujoco>"""


@pytest.fixture
def chain(tmp_path):
    path = tmp_path / "chain.xml"
    path.write_text(_CHAIN)
    return load_mjcf_quietly(path)


def test_keyframe_chain_is_placed_and_mapped_exactly(chain):
    """A keyframe away from qpos0, with velocities: the frames sit at MuJoCo's partial body
    poses (every joint holds at 1e-12, the abdsim joints read zero), qpos/qvel map back to
    the keyframe's, joints and frames are in MuJoCo's order, and set_world_state places the
    frames of another state exactly."""
    result, model = chain, chain.model
    assert result.joint_names == ["slide_x", "yaw", "pitch", "roll", "ball"]
    names = result.names
    assert names[:2] == ["base", "link"] and len(names) == 5  # 2 + 1 frames
    chain_of = [(j.name, j.parent, j.child) for j in result.joints]
    f1, f2, f3 = (names.index(f"{b} (joint frame after {j!r})") for b, j in
                  [("base", "slide_x"), ("base", "yaw"), ("link", "roll")])  # fmt: skip
    assert chain_of == [
        ("slide_x", None, f1), ("yaw", f1, f2), ("pitch", f2, 0), ("roll", 0, f3), ("ball", f3, 1),
    ]  # fmt: skip
    world = result.make_world(integrator="bdf2", contact=False, dt=DT)
    assert max(world.joint_violation()) < 1e-12
    np.testing.assert_allclose(world.joint_positions(), [0, 0, 0, 0, 1, 0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(result.qpos_from_world(world), model.key_qpos[0], atol=1e-12)
    np.testing.assert_allclose(result.qvel_from_world(world), model.key_qvel[0], atol=1e-12)
    rng = np.random.default_rng(1)
    q = np.array(model.key_qpos[0]) + np.r_[rng.uniform(-0.3, 0.3, 4), 0, 0, 0, 0]
    q[4:] = [np.cos(0.2), 0.0, 0.0, np.sin(0.2)]
    v = rng.uniform(-1.0, 1.0, model.nv)
    result.set_world_state(world, q, v)
    assert max(world.joint_violation()) < 1e-12
    np.testing.assert_allclose(result.qpos_from_world(world), q, atol=1e-12)
    np.testing.assert_allclose(result.qvel_from_world(world), v, atol=1e-12)


def test_chains_move_like_mujoco_with_their_joint_physics(tmp_path):
    """Damping, armature, a spring, a limit, actuators and joint sensors act on each joint of
    the chains as in MuJoCo (the link on a universal joint: roll, then yaw about the same
    point): 0.3 s from the keyframe's state under constant control, every joint within 2e-3
    of MuJoCo RK4 (measured 6.6e-4; 5.6e-4 with frames at 1e-6 of the mass, 1.8e-4 at
    dt = 2.5e-4: mostly BDF2's error) and the sensors read MuJoCo's values.

    Loaded at qpos0 and put in the keyframe's state by set_world_state: abdsim's position
    actuator acts on the joint coordinate relative to the load, MuJoCo's on the absolute
    one, so a load away from qpos0 would shift its target."""
    path = tmp_path / "universal.xml"
    path.write_text(
        _CHAIN.replace('type="ball" pos="0 0.1 0"', 'type="hinge" axis="0 0 1" pos="-0.05 0 0"')
        .replace("0.2 0.9238795 0 0.3826834 0", "0.2 0.3")
        .replace("0.6 0.3 -0.2 0.1", "0.6 -0.5")
    )
    result = load_mjcf_quietly(path, keyframe=None)
    model = result.model
    world = result.make_world(integrator="bdf2", contact=False, dt=DT)
    physics = {j.name: (j.damping, j.armature, j.stiffness) for j in world.joints}
    for j in range(model.njnt):
        dof = model.jnt_dofadr[j]
        expect = (model.dof_damping[dof], model.dof_armature[dof], model.jnt_stiffness[j])
        assert physics[model.joint(j).name] == pytest.approx(expect)
    assert next(j.limits for j in world.joints if j.name == "pitch") == pytest.approx((-1, 1))
    assert result.actuator_names == ["m_yaw", "p_pitch"]
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    result.set_world_state(world, data.qpos, data.qvel)
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    world.ctrl[:] = data.ctrl[:] = [0.05, -0.2]
    worst = worst_qpos_error(result, world, model, data, 300)
    assert data.nefc == 0  # the limit (1 rad away) never acted
    mujoco.mj_forward(model, data)
    assert np.abs(data.qpos - model.key_qpos[0]).max() > 0.3  # it moved
    assert worst < 2e-3, worst
    assert world.sensor_names == ["s_pitch", "s_yaw"]
    np.testing.assert_allclose(world.sensordata, data.sensordata, atol=5e-3)


def test_frames_collide_with_nothing_and_keep_the_mass(tmp_path):
    """humanoid: one note names the bodies on several joints; each frame carries
    FRAME_MASS_FRACTION of its body's mass and the totals are MuJoCo's; a frame never
    collides (every pair and the ground excluded), and MuJoCo's parent–child filter still
    holds between the real bodies across the frames (pelvis–thigh), with the feet still
    colliding with each other."""
    result = load_mjcf_quietly(suite_xml("humanoid.xml"))
    model = result.model
    notes = [n for n in result.notes if "bodies moved by several joints" in n]
    assert len(notes) == 1
    several = [b for b in range(model.nbody) if model.body_jntnum[b] > 1]
    assert all(repr(model.body(b).name) in notes[0] for b in several)
    frames = [i for i, b in enumerate(result.bodies) if "(joint frame after" in b.name]
    assert len(frames) == sum(int(model.body_jntnum[b]) - 1 for b in several)
    masses = [to_rigid_body(b.geometry).mass for b in result.bodies]
    assert sum(masses) == pytest.approx(float(model.body_mass[1:].sum()), rel=1e-12)
    thigh = result.index("right_thigh")
    frame_of_thigh = [i for i in frames if result.bodies[i].name.startswith("right_thigh ")]
    assert len(frame_of_thigh) == 2
    for i in frame_of_thigh:
        thigh_mass = float(model.body_mass[model.body("right_thigh").id])
        assert masses[i] == pytest.approx(FRAME_MASS_FRACTION * thigh_mass, rel=1e-12)
    rules = result.contact_rules
    n = len(result.bodies)
    for f in frames:
        assert f in rules.ground_excluded
        assert all((min(f, j), max(f, j)) in rules.excluded for j in range(n) if j != f)
    pelvis = result.index("pelvis")
    assert (min(pelvis, thigh), max(pelvis, thigh)) in rules.excluded
    feet = sorted((result.index("right_foot"), result.index("left_foot")))
    assert tuple(feet) not in rules.excluded
