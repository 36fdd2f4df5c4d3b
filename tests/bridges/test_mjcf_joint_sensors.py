"""MJCF joint sensors (jointpos, jointvel, actuatorfrc) against MuJoCo on a pendulum driven by
a position actuator: abdsim BDF2 on the scene from build_articulated_scene (with the same
actuator added by Scene.add_actuator) vs MuJoCo RK4 on the same file, dt = 1e-3, over 1 s."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest

import abdsim
from abdsim.bridges import build_articulated_scene, load_mjcf

KP = 5.0
TARGET = 0.6  # rad
PENDULUM = f"""<mujoco><option timestep="1e-3" integrator="RK4"/><compiler angle="radian"/>
  <worldbody><body name="arm" pos="0 0 1">
    <joint name="swing" type="hinge" axis="0 1 0"/>
    <geom type="box" size="0.03 0.03 0.2" pos="0 0 -0.2" density="1000"/>
  </body></worldbody>
  <actuator><position name="servo" joint="swing" kp="{KP}"/></actuator>
  <sensor>
    <jointpos name="angle" joint="swing"/>
    <jointvel name="rate" joint="swing"/>
    <actuatorfrc name="servo_force" actuator="servo"/>
  </sensor></mujoco>"""


@pytest.fixture
def pendulum(tmp_path):
    path = tmp_path / "pendulum.xml"
    path.write_text(PENDULUM)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = load_mjcf(path, kappa=1e10)
    return path, result


def test_joint_sensors_match_mujoco_on_a_driven_pendulum(pendulum):
    """The servo swings the 1.44 kg arm towards 0.6 rad, undamped (about 1.5 periods, up to
    0.78 rad and 3.9 rad/s): jointpos within 1e-3 rad of MuJoCo's at every step (the joint
    test's tolerance: BDF2 vs RK4 at dt = 1e-3; measured 1.4e-4), jointvel within 1e-2 rad/s
    (1.5e-3), actuatorfrc = kp (u − θ) within kp × 1e-3 N·m (7e-4); MuJoCo's layout."""
    path, result = pendulum
    scene = build_articulated_scene(result, integrator="bdf2", contact=False)
    (servo,) = scene.actuators  # the MJCF's own position actuator (bridges/_mjcf_actuators.py)
    assert (servo.index, servo.kind, servo.kp, servo.kv, servo.gear) == (0, "position", KP, 0, 1)
    world = abdsim.World(scene)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    np.testing.assert_array_equal(world.sensor_adr, model.sensor_adr)
    np.testing.assert_array_equal(world.sensor_dim, model.sensor_dim)
    world.ctrl[0] = data.ctrl[0] = TARGET
    worst, peak = np.zeros(3), 0.0
    for _ in range(1000):
        world.step()
        mujoco.mj_step(model, data)
        mujoco.mj_forward(model, data)  # sensors at the state after the step
        worst = np.maximum(worst, np.abs(world.sensordata - data.sensordata))
        peak = max(peak, data.sensordata[0])
    assert worst[0] < 1e-3, worst
    assert worst[1] < 1e-2, worst
    assert worst[2] < KP * 1e-3, worst
    assert peak > 0.5  # it swung


def test_joint_sensors_read_nan_without_joints_and_are_checked(pendulum):
    """A scene without the joint (kinematic=True: the arm is scripted) keeps the slots as NaN;
    World.add_joint_sensor refuses a joint or actuator the World does not have."""
    path, result = pendulum
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scripted = load_mjcf(path, kappa=1e10, kinematic=True)
    world = abdsim.World(scripted.build_scene(contact=False))
    assert np.isnan(world.sensordata).all()
    world = abdsim.World(build_articulated_scene(result, contact=False))
    i = world.add_joint_sensor("jointvel", "swing", name="again")
    assert world.sensordata[world.sensor_adr[i]] == 0.0
    with pytest.raises(ValueError, match="no joint named 'elbow'"):
        world.add_joint_sensor("jointpos", "elbow")
    with pytest.raises(ValueError, match="actuator 1 out of range"):
        world.add_joint_sensor("actuatorfrc", 1)
    with pytest.raises(ValueError, match="add_joint_sensor"):
        world.add_sensor("jointpos", 0)


GENERAL = """<mujoco><option timestep="1e-3" integrator="RK4"/><compiler angle="radian"/>
  <worldbody><body name="arm" pos="0 0 1">
    <joint name="swing" type="hinge" axis="0 1 0"/>
    <geom type="box" size="0.03 0.03 0.2" pos="0 0 -0.2" density="1000"/>
    <site name="tip" pos="0 0 -0.4"/>
  </body></worldbody>
  <actuator>
    <motor name="thruster" site="tip" gear="0 0 1 0 0 0"/>
    <general name="filtered" joint="swing" dyntype="filter" dynprm="0.1"/>
    <general name="servo" joint="swing" gear="2" gainprm="10" biastype="affine"
             biasprm="0 -5 -0.2"/>
  </actuator>
  <sensor>
    <actuatorfrc name="servo_force" actuator="servo"/>
    <actuatorfrc name="filtered_force" actuator="filtered"/>
  </sensor></mujoco>"""


def test_actuatorfrc_follows_the_loaded_actuator_and_its_gear(tmp_path):
    """MuJoCo actuator 2 (a ``general`` servo with gear 2, mapped onto a position preset by
    rescaling its gear) is abdsim's joint actuator 0 (the site thruster and the filtered one
    come first in MuJoCo's order): its actuatorfrc reads MuJoCo's actuator-space force
    (10 u − 5 L − 0.2 L̇, L = 2 θ) within 5e-3 N over 0.5 s; the filtered actuator is not
    modelled, so its sensor is NaN with a note."""
    path = tmp_path / "general.xml"
    path.write_text(GENERAL)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = load_mjcf(path, kappa=1e10)
    assert any("filtered_force" in note for note in result.notes)
    world = abdsim.World(build_articulated_scene(result, integrator="bdf2", contact=False))
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    world.ctrl[0] = data.ctrl[2] = 0.3
    worst, peak = 0.0, 0.0
    for _ in range(500):
        world.step()
        mujoco.mj_step(model, data)
        mujoco.mj_forward(model, data)
        assert np.isnan(world.sensordata[1]) and np.isfinite(world.sensordata[0])
        worst = max(worst, abs(world.sensordata[0] - data.sensordata[0]))
        peak = max(peak, abs(data.sensordata[0]))
    assert worst < 5e-3, worst
    assert peak > 1.0  # the servo pushed
