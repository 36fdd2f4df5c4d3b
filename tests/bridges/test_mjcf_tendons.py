"""MJCF actuators on fixed tendons that move one joint are that joint's actuators
(bridges/_mjcf_tendons.py): checked against MuJoCo RK4; other tendons stay named in the notes."""

from __future__ import annotations

import numpy as np
import pytest

from .conftest import load_mjcf_quietly, suite_xml, worst_qpos_error

mujoco = pytest.importorskip("mujoco")

_PENDULUM = """<mujoco><compiler angle="radian"/><option timestep="1e-3" integrator="RK4"/>
  <worldbody><body name="arm" pos="0 0 1">
    <joint name="swing" type="hinge" axis="0 1 0" damping="0.05"/>
    <geom type="box" size="0.03 0.03 0.2" pos="0 0 -0.2" mass="1"/>
    <body name="tip" pos="0 0 -0.4">
      <joint name="bend" type="hinge" axis="0 1 0"/>
      <geom type="box" size="0.02 0.02 0.1" pos="0 0 -0.1" mass="0.2"/>
    </body>
  </body></worldbody>
  <tendon>
    <fixed name="scaled"><joint joint="swing" coef="-2"/><joint joint="bend" coef="0"/></fixed>
    <fixed name="coupled"><joint joint="swing" coef="1"/><joint joint="bend" coef="1"/></fixed>
    <fixed name="sprung" stiffness="3"><joint joint="bend" coef="1"/></fixed>
  </tendon>
  <actuator>
    <position name="servo" tendon="scaled" kp="4" gear="1.5"/>
    <motor name="pair" tendon="coupled"/>
    <motor name="bender" tendon="sprung" gear="0.5"/>
  </actuator></mujoco>"""


def test_one_joint_tendon_actuators_match_mujoco(tmp_path):
    """A position servo on tendon L = -2·swing (gear 1.5) and a motor through a one-joint
    tendon with its own spring: the servo and the motor are joint actuators with gear × coef
    (-3 and 0.5); the tendon coupling two joints and the spring of the sprung tendon are not
    simulated, each named. Without the unmodelled ones (ctrl 0 on 'pair', the spring's
    stiffness zeroed in MuJoCo too) 1 s under constant control matches MuJoCo RK4: both
    joints within 3e-3 rad while the tip swings 0.7 rad (measured 1.4e-3, and 3.0e-4 at
    dt = 2.5e-4: BDF2's error)."""
    path = tmp_path / "pendulum.xml"
    path.write_text(_PENDULUM)
    result = load_mjcf_quietly(path)
    assert result.actuator_names == ["servo", "bender"]
    gears = {a.name: (a.joint, a.kind, a.gear, a.kp) for a in result.actuators}
    assert gears["servo"][:3] == ("swing", "position", pytest.approx(-3.0))
    assert gears["bender"] == ("bend", "motor", pytest.approx(0.5), 0.0)
    assert any("'pair'" in n and "couples 2 joints" in n for n in result.notes)
    (tendon_note,) = [n for n in result.notes if "tendon(s) not simulated" in n]
    assert "'coupled'" in tendon_note and "'sprung'" in tendon_note
    assert "'scaled'" not in tendon_note  # only a transmission: modelled
    model = result.model
    model.tendon_stiffness[:] = 0.0
    world = result.make_world(integrator="bdf2", contact=False, dt=1e-3)
    data = mujoco.MjData(model)
    data.ctrl[:] = [0.3, 0.0, 0.2]
    world.ctrl[:] = data.ctrl[result.actuator_ids]
    worst = worst_qpos_error(result, world, model, data, 1000)
    assert np.abs(data.qpos).max() > 0.1  # it moved
    assert worst < 3e-3, worst


def test_point_mass_motors_reach_both_slides():
    """dm_control point_mass drives root_x and root_y through tendons t1, t2 (coef 1 on one
    joint, 0 on the other): both motors are on world.ctrl with gear 0.1, no tendon noted."""
    result = load_mjcf_quietly(suite_xml("point_mass.xml"))
    assert [(a.name, a.joint, a.gear) for a in result.actuators] == [
        ("t1", "root_x", pytest.approx(0.1)),
        ("t2", "root_y", pytest.approx(0.1)),
    ]
    assert not any("tendon" in n for n in result.notes)
