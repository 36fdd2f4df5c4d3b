"""URDF joints hung from massless links without geometry become joint frames
(``bridges/_urdf_joint_frames.py``): example-robot-data's ``human.urdf`` (19 of its 37 links are
such ``*_virtual`` links, making its hips, shoulders, spine and neck chains of revolute joints)
loads as a dynamic articulation and swings like Pinocchio's ABA."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from abdsim.bridges import load_urdf
from abdsim.bridges._joint_frames import FRAME_MASS_FRACTION
from tests.joints.conftest import aba_rk4

from .conftest import ROBOTS


def _human():
    if ROBOTS is None:
        pytest.skip("example-robot-data is not installed")
    path = ROBOTS / "human_description" / "robots" / "human.urdf"
    if not path.is_file():
        pytest.skip(f"{path} not shipped by this example-robot-data")
    return path


def _load(**kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = load_urdf(_human(), **kwargs)
    return result, [str(w.message) for w in caught]


def test_virtual_links_become_frames_and_the_mass_is_the_sources():
    """One body per Pinocchio joint (36 joints + the fixed pelvis), the frames named in a note,
    and the robot's total mass exactly Pinocchio's."""
    result, notes = _load()
    model = result.model
    assert result.articulated and len(result.bodies) == model.njoints == 37
    assert len(result.joint_names) == 36
    frames = [b for b in result.bodies if b.name.endswith("_virtual") or "_virtual_" in b.name]
    assert len(frames) == 19
    assert all(not b.geoms for b in frames)  # they collide with nothing
    assert any("left_upperleg_virtual_2" in n and "joint frame" in n for n in notes)
    from abdsim.constitution.rigid_body import to_rigid_body

    moving = [to_rigid_body(b.geometry) for b in result.bodies[1:]]
    total = sum(r.mass for r in moving)
    source = sum(model.inertias[j].mass for j in range(1, model.njoints))
    assert abs(total - source) < 1e-12 * source
    # Each frame carries FRAME_MASS_FRACTION of its donor's (first massive link below) mass.
    upperleg = next(b for b in result.bodies if b.name == "left_upperleg")
    hip_frame = next(b for b in result.bodies if b.name == "left_upperleg_virtual")
    m_leg = to_rigid_body(upperleg.geometry).mass
    m_frame = to_rigid_body(hip_frame.geometry).mass
    assert m_frame == pytest.approx(FRAME_MASS_FRACTION * 9.22, rel=1e-12)
    assert m_leg == pytest.approx((1 - 2 * FRAME_MASS_FRACTION) * 9.22, rel=1e-12)


def test_human_swings_like_pinocchio_aba():
    """Fixed pelvis, released at rest from mid-limit angles, no contact: 0.15 s at dt = 1e-3
    against Pinocchio ABA + RK4 (the spine and hips move by up to ~0.6 rad and no joint reaches
    a limit in the reference). Every joint within 1e-3 rad (2.5e-4 measured; 5e-2 with frames
    carrying 3e-2 of their donors), joint violation at round-off."""
    probe, _ = _load(kinematic=True)
    model = probe.model
    q0 = 0.5 * (np.array(model.lowerPositionLimit) + np.array(model.upperPositionLimit))
    result, _ = _load(q=q0)
    dt, steps = 1e-3, 150
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        world = result.make_world(integrator="bdf2", dt=dt, gravity=(0, 0, -9.81), contact=False)
    model.gravity.linear = np.array([0.0, 0.0, -9.81])
    reference = aba_rk4(model, q0, np.zeros(model.nv), steps * dt, dt, 1)
    lower, upper = np.array(model.lowerPositionLimit), np.array(model.upperPositionLimit)
    assert (reference > lower + 0.02).all() and (reference < upper - 0.02).all()
    worst = 0.0
    for k in range(1, steps + 1):
        world.step()
        worst = max(worst, np.abs(result.qpos_from_world(world) - reference[k]).max())
    assert np.abs(reference[-1] - q0).max() > 0.3  # it swung
    assert worst < 1e-3, worst
    assert max(world.joint_violation()) <= 1e-6
