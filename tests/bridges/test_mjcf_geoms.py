"""MJCF planes at any orientation, height fields, and the elements named in the notes."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import trimesh

from abdsim.bridges import load_mjcf


def _mjcf(tmp_path, body, assets="", extra=""):
    path = tmp_path / "s.xml"
    path.write_text(f"<mujoco><asset>{assets}</asset><worldbody>{body}</worldbody>{extra}</mujoco>")
    return path


def test_height_field_is_a_fixed_closed_solid_of_the_right_volume(tmp_path):
    # 3x3 grid over [-2, 2] x [-1, 1], only the centre raised to size[2] = 0.5, base 0.1:
    # volume = base * area + size[2] * (integral of the centre's hat function) and that
    # integral is (1/3) * (area of the 6 triangles around the centre) = sx * sy.
    path = _mjcf(
        tmp_path,
        '<geom name="terrain" type="hfield" hfield="h"/>'
        '<body pos="0 0 2"><freejoint/><geom size="0.1"/></body>',
        assets='<hfield name="h" nrow="3" ncol="3" size="2 1 0.5 0.1" '
        'elevation="0 0 0 0 1 0 0 0 0"/>',
    )
    res = load_mjcf(path)
    body = res.bodies[res.index("terrain")]
    assert body.kind == "fixed"
    g = body.geometry
    mesh = trimesh.Trimesh(g.positions, g.triangles, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume == pytest.approx(0.1 * 4 * 2 + 0.5 * 2 * 1, rel=1e-12)
    assert g.positions[:, 2].max() == pytest.approx(0.5)
    assert g.positions[:, 2].min() == pytest.approx(-0.1)


@pytest.mark.parametrize("tilt", [30.0, 90.0])
def test_tilted_plane_is_a_fixed_box_under_its_rectangle(tmp_path, tilt):
    path = _mjcf(
        tmp_path,
        '<geom name="floor" type="plane" size="3 3 0.1"/>'
        f'<geom name="wall" type="plane" size="0.5 0.4 0.1" pos="1 0 0.5" euler="0 {tilt} 0"/>'
        '<body pos="0 0 0.3"><freejoint/><geom size="0.1"/></body>',
    )
    with pytest.warns(UserWarning, match=r"plane 'wall' .* fixed thin box"):
        res = load_mjcf(path)
    assert [g.name for g in res.grounds] == ["floor"]
    body = res.bodies[res.index("wall")]
    T = body.transform
    V = body.geometry.positions @ T[:3, :3].T + T[:3, 3]
    a = np.radians(tilt)
    normal = np.array([np.sin(a), 0.0, np.cos(a)])  # the plane's z axis after euler y
    height = V @ normal - normal @ np.array([1.0, 0.0, 0.5])
    assert height.max() == pytest.approx(0.0, abs=1e-12)  # top face on the plane
    assert height.min() == pytest.approx(-0.04, abs=1e-12)  # 0.1 x the smaller half-extent
    in_plane = V - np.outer(V @ normal, normal)
    assert np.ptp(in_plane[:, 1]) == pytest.approx(0.8)  # the rectangle's 2 x 0.4
    res.make_world().step(1)  # builds: no "only a z-up ground" refusal


def test_tendons_equalities_and_actuators_are_named_and_warned_once(tmp_path):
    path = _mjcf(
        tmp_path,
        '<body name="a" pos="0 0 1"><joint name="h1" type="hinge"/><geom size="0.1"/>'
        '<body name="b" pos="0.3 0 0"><joint name="h2" type="hinge"/><geom size="0.1"/>'
        "</body></body>",
        extra='<tendon><fixed name="t"><joint joint="h1" coef="1"/><joint joint="h2" '
        'coef="-1"/></fixed></tendon><equality><joint name="eq" joint1="h1" joint2="h2"/>'
        '</equality><actuator><motor name="m1" joint="h1"/></actuator>',
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = load_mjcf(path, kinematic=True)
    messages = [str(w.message) for w in caught]
    assert len(messages) == len(set(messages)) == len(res.notes)  # each note warned once
    assert any("1 tendon(s) not simulated: ['t']" in n for n in res.notes)
    assert any("equality constraint(s) not simulated: ['eq (joint)']" in n for n in res.notes)
    assert any("actuator(s) not simulated" in n and "'m1'" in n for n in res.notes)
    # Articulated (the default) the motor is simulated: on world.ctrl, no note.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = load_mjcf(path)
    assert len(caught) == len({str(w.message) for w in caught}) == len(res.notes)
    assert res.actuator_names == ["m1"] and not any("actuator" in n for n in res.notes)
    assert any("1 tendon(s) not simulated: ['t']" in n for n in res.notes)
