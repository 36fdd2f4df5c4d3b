"""Every bad input of the loaders raises a clear error that names the element."""

from __future__ import annotations

import shutil
import warnings

import numpy as np
import pytest

from abdsim.bridges import LoaderError, MjcfDriver, RobotDriver, load_mjcf, load_urdf

LINK = """
  <link name="{name}">
    <inertial><mass value="{mass}"/>
      <inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>
    <collision><geometry>{geometry}</geometry></collision>
  </link>"""


def urdf(tmp_path, *links, joints="", name="r.urdf"):
    path = tmp_path / name
    path.write_text(f'<?xml version="1.0"?>\n<robot name="r">{"".join(links)}{joints}</robot>')
    return path


def link(name="base", mass=1.0, ixx=0.01, iyy=0.01, izz=0.01, geometry='<box size="0.1 0.1 0.1"/>'):
    return LINK.format(name=name, mass=mass, ixx=ixx, iyy=iyy, izz=izz, geometry=geometry)


def revolute(parent, child):
    return (
        f'<joint name="{child}_joint" type="revolute"><parent link="{parent}"/>'
        f'<child link="{child}"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
    )


# -- URDF ------------------------------------------------------------------------------------
def test_missing_urdf_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="URDF file not found"):
        load_urdf(tmp_path / "nope.urdf")


def test_malformed_urdf(tmp_path):
    (tmp_path / "bad.urdf").write_text("<robot name='r'><link name='a'></robot>")
    with pytest.raises(LoaderError, match="malformed URDF"):
        load_urdf(tmp_path / "bad.urdf")
    (tmp_path / "notrobot.urdf").write_text("<mujoco/>")
    with pytest.raises(LoaderError, match="expected <robot>"):
        load_urdf(tmp_path / "notrobot.urdf")


def test_missing_mesh_file_names_link_and_file(tmp_path):
    path = urdf(tmp_path, link("base", geometry='<mesh filename="package://pkg/gone.stl"/>'))
    with pytest.raises(FileNotFoundError, match=r"link 'base'.*package://pkg/gone.stl"):
        load_urdf(path)


def test_unsupported_geometry_names_link(tmp_path):
    path = urdf(tmp_path, link("base", geometry='<capsule radius="0.1" length="0.2"/>'))
    with pytest.raises(LoaderError, match=r"link 'base'.*unsupported collision geometry <capsule>"):
        load_urdf(path)


@pytest.mark.parametrize(
    ("inertia", "expected"),
    [
        # Principal moments λ -> second moments Σ_i = (λ_j + λ_k - λ_i)/2, each raised to
        # m (0.01 L)² = 3e-6 (L = the 0.1 m cube's diagonal), then λ_i = Σ_j + Σ_k.
        ({"ixx": -0.01}, [6e-6, 0.015003, 0.015003]),
        ({"ixx": 0.01, "iyy": 0.01, "izz": 0.05}, [0.025003, 0.025003, 0.05]),
        # On the triangle equality (a lamina): Σ_z = 0, a singular mass matrix unrepaired.
        ({"ixx": 0.01, "iyy": 0.02, "izz": 0.03}, [0.010003, 0.020003, 0.03]),
    ],
)
def test_degenerate_link_inertia_is_bounded_with_a_note(tmp_path, inertia, expected):
    path = urdf(tmp_path, link("base"), link("arm", **inertia), joints=revolute("base", "arm"))
    with pytest.warns(UserWarning, match=r"body 'arm' \(links \['arm'\]\): degenerate inertia"):
        res = load_urdf(path)
    moments = np.linalg.eigvalsh(res.bodies[res.index("arm")].geometry.meta["inertia"])
    np.testing.assert_allclose(moments, expected, rtol=1e-9)
    assert any("degenerate inertia" in n and "'arm'" in n for n in res.notes)


def test_point_mass_link_is_checked_in_its_group_not_alone(tmp_path):
    """A sensor frame's point mass (zero inertia) fixed to a link: the group is physical."""
    sensor = (
        '<link name="sensor"><inertial><origin xyz="0.05 0 0"/><mass value="0.01"/>'
        '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>'
        '<joint name="fix" type="fixed"><parent link="arm"/><child link="sensor"/></joint>'
    )
    path = urdf(tmp_path, link("base"), link("arm"), sensor, joints=revolute("base", "arm"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no repair, no note
        res = load_urdf(path)
    body = res.bodies[res.index("arm")]
    assert "sensor" in body.links
    # Exact combination (parallel axes): m = 1.01, c = 0.01*0.05/1.01 along x.
    m, cx = 1.01, 0.01 * 0.05 / 1.01
    d_arm, d_sensor = cx, 0.05 - cx
    expected = np.diag([0.01, 0.01 + d_arm**2 + 0.01 * d_sensor**2, 0.0])
    expected[2, 2] = expected[1, 1]
    assert body.geometry.meta["mass"] == pytest.approx(m, rel=1e-12)
    np.testing.assert_allclose(body.geometry.meta["mass_center"], [cx, 0, 0], atol=1e-12)
    np.testing.assert_allclose(body.geometry.meta["inertia"], expected, rtol=1e-9, atol=1e-15)
    assert not res.notes


def test_negative_mass_names_link(tmp_path):
    path = urdf(tmp_path, link("base", mass=-1.0))
    with pytest.raises(LoaderError, match=r"link 'base': mass must be finite and >= 0"):
        load_urdf(path)


def test_moving_link_with_geometry_but_no_inertial(tmp_path):
    bare = (
        '<link name="arm"><collision><geometry><box size="0.1 0.1 0.1"/></geometry>'
        "</collision></link>"
    )
    path = urdf(tmp_path, link("base"), bare, joints=revolute("base", "arm"))
    # Repaired, not refused: the geometry's mass at 1000 kg/m^3, with a note naming the link.
    with pytest.warns(UserWarning, match=r"links \['arm'\].*no mass.*without <inertial>"):
        res = load_urdf(path)
    assert res.bodies[1].geometry.meta["mass"] == pytest.approx(1000.0 * 1e-3)
    res = load_urdf(path, mass_density=500.0)  # ... or at the density asked for
    assert res.bodies[1].geometry.meta["mass"] == pytest.approx(500.0 * 1e-3)
    assert not any("no mass" in n for n in res.notes)


def test_link_with_mass_but_no_geometry_is_reported(tmp_path):
    ghost = link("ghost").replace(
        '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>', ""
    )
    path = urdf(tmp_path, link("base"), ghost, joints=revolute("base", "ghost"))
    with pytest.warns(UserWarning, match="'ghost'.*no collision geometry"):
        res = load_urdf(path, kinematic=True)
    assert res.names == ["base"] and "ghost" in res.notes[0]
    # Articulated, the link keeps its mass and joint: a body whose surface is its inertia box
    # (here the 1 kg, 0.01 kg m² cube of side sqrt(0.06)), colliding with nothing.
    with pytest.warns(UserWarning, match="'ghost'.*inertia box, which collides with nothing"):
        res = load_urdf(path)
    assert res.names == ["base", "ghost"] and res.bodies[1].geoms == ()
    assert res.bodies[1].geometry.meta["mass"] == pytest.approx(1.0)
    side = np.ptp(res.bodies[1].geometry.positions, axis=0)
    np.testing.assert_allclose(side, np.sqrt(0.06), rtol=1e-12)
    assert (0, 1) in res.contact_rules.excluded
    assert res.joint_names == ["ghost_joint"]


def test_massless_link_between_joints_becomes_a_joint_frame(tmp_path):
    """A link with neither mass nor geometry between two joints (URDF multi-axis joints) is
    a joint frame carrying 1e-4 of the first massive link below it, named in a note."""
    ghost = link("ghost", mass=0.0).replace(
        '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>', ""
    )
    joints = revolute("base", "ghost") + revolute("ghost", "tip")
    path = urdf(tmp_path, link("base"), ghost, link("tip"), joints=joints, name="gap.urdf")
    carry = r"neither mass nor geometry that carry a joint \['ghost'\]"
    with pytest.warns(UserWarning, match=carry):
        res = load_urdf(path)
    assert res.names == ["base", "ghost", "tip"] and res.bodies[1].geoms == ()
    assert res.bodies[1].geometry.meta["mass"] == pytest.approx(1e-4, rel=1e-12)
    assert res.bodies[2].geometry.meta["mass"] == pytest.approx(1.0 - 1e-4, rel=1e-12)
    assert res.joint_names == ["ghost_joint", "tip_joint"]


def test_massless_link_with_nothing_massive_below_is_refused_naming_it(tmp_path):
    """No massive link below the massless one: nothing to take a frame's mass from."""
    ghost = link("ghost", mass=0.0).replace(
        '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>', ""
    )
    joints = revolute("base", "ghost") + revolute("ghost", "tip")
    tip = link("tip", mass=0.0)
    path = urdf(tmp_path, link("base"), ghost, tip, joints=joints, name="gap.urdf")
    with pytest.raises(
        LoaderError,
        match="gap.urdf: joint 'tip_joint' hangs from joint "
        "'ghost_joint', whose links have neither mass nor collision",
    ):
        load_urdf(path)
    assert load_urdf(path, kinematic=True).names == ["base", "tip"]


def test_planar_joint_is_refused_as_articulation_naming_it(tmp_path):
    joint = (
        '<joint name="plane" type="planar"><parent link="base"/><child link="puck"/>'
        '<axis xyz="0 0 1"/></joint>'
    )
    path = urdf(tmp_path, link("base"), link("puck"), joints=joint, name="planar.urdf")
    with pytest.raises(
        LoaderError,
        match=r"planar.urdf: joint 'plane' \(body 'puck'\): type "
        r"'other' \(Pinocchio JointModelPlanar\) is not supported",
    ):
        load_urdf(path)
    assert [b.kind for b in load_urdf(path, kinematic=True).bodies] == ["fixed", "kinematic"]


def test_no_collision_geometry_at_all(tmp_path):
    path = tmp_path / "empty.urdf"
    path.write_text('<robot name="r"><link name="a"/></robot>')
    with pytest.raises(LoaderError, match="no link with collision geometry"):
        load_urdf(path)


def test_bad_configuration(tmp_path):
    path = urdf(tmp_path, link("base"), link("arm"), joints=revolute("base", "arm"))
    with pytest.raises(LoaderError, match="q must have 1 entries"):
        load_urdf(path, q=[0.0, 1.0])
    with pytest.raises(LoaderError, match="NaN"):
        load_urdf(path, q=[np.nan])
    with pytest.raises(ValueError, match="open_mesh"):
        load_urdf(path, open_mesh="ignore")


def test_open_mesh_is_hulled_with_a_warning_or_refused(tmp_path, data_dir):
    import trimesh

    mesh = trimesh.creation.box((0.1, 0.1, 0.1))
    open_mesh = trimesh.Trimesh(mesh.vertices, mesh.faces[:-2])  # a box missing one side
    open_mesh.export(tmp_path / "open.stl")
    path = urdf(tmp_path, link("base", geometry='<mesh filename="open.stl"/>'))
    with pytest.warns(UserWarning, match="not a closed surface.*convex hull"):
        res = load_urdf(path)
    assert res.bodies[0].geometry.meta["volume"] == pytest.approx(1e-3)
    with pytest.raises(LoaderError, match="not a closed"):
        load_urdf(path, open_mesh="error")


def test_driver_rejects_bad_trajectories(data_dir):
    with pytest.raises(ValueError, match="arm.urdf was loaded as a dynamic articulation"):
        RobotDriver(load_urdf(data_dir / "arm.urdf"), np.zeros((3, 2)), dt=0.1)
    res = load_urdf(data_dir / "arm.urdf", kinematic=True)
    with pytest.raises(ValueError, match=r"shape \(T, 2\)"):
        RobotDriver(res, np.zeros((3, 5)), dt=0.1)
    with pytest.raises(ValueError, match="times= or a uniform dt="):
        RobotDriver(res, np.zeros((3, 2)))
    with pytest.raises(ValueError, match="strictly increasing"):
        RobotDriver(res, np.zeros((3, 2)), times=[0, 1, 1])
    with pytest.raises(ValueError, match="NaN"):
        RobotDriver(res, np.full((2, 2), np.nan), dt=0.1)
    with pytest.raises(ValueError, match="expected 2 finite"):
        RobotDriver(res, lambda t: [0.0]).targets(0.0)
    with pytest.raises(ValueError, match="MjcfDriver drives an MJCF"):
        MjcfDriver(res, np.zeros((1, 2)))


# -- MJCF ------------------------------------------------------------------------------------
def mjcf(tmp_path, body, assets="", name="s.xml"):
    path = tmp_path / name
    path.write_text(f"<mujoco><asset>{assets}</asset><worldbody>{body}</worldbody></mujoco>")
    return path


def test_missing_and_malformed_mjcf(tmp_path):
    with pytest.raises(FileNotFoundError, match="MJCF file not found"):
        load_mjcf(tmp_path / "nope.xml")
    (tmp_path / "bad.xml").write_text("<mujoco><worldbody><body></worldbody></mujoco>")
    with pytest.raises(LoaderError, match="MuJoCo could not load"):
        load_mjcf(tmp_path / "bad.xml")


def test_missing_mesh_file_in_mjcf(tmp_path):
    path = mjcf(
        tmp_path,
        '<body><freejoint/><geom type="mesh" mesh="m"/></body>',
        assets='<mesh name="m" file="gone.stl"/>',
    )
    with pytest.raises(FileNotFoundError, match="gone.stl"):
        load_mjcf(path)


def test_plane_on_a_moving_body_is_refused_naming_it(tmp_path):
    path = mjcf(
        tmp_path,
        '<body name="b"><freejoint/><geom name="p" type="plane" size="1 1 1"/>'
        '<geom type="sphere" size="0.1"/></body>',
    )
    with pytest.raises(LoaderError, match=r"(?s)plane only allowed in static bodies.*'p'"):
        load_mjcf(path)


def test_non_physical_inertia_is_rejected_with_its_body(tmp_path):
    path = mjcf(
        tmp_path,
        '<body name="odd"><freejoint/><geom type="sphere" size="0.1"/>'
        '<inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.05"/></body>',
    )
    with pytest.raises(LoaderError, match=r"(?s)inertia must satisfy A \+ B >= C.*'odd'"):
        load_mjcf(path)


def test_free_body_without_collision_geometry(tmp_path):
    path = mjcf(
        tmp_path,
        '<body name="ghost"><freejoint/><geom type="sphere" size="0.1" contype="0" '
        'conaffinity="0"/></body><geom type="box" size="1 1 0.1"/>',
    )
    with pytest.raises(LoaderError, match=r"body 'ghost' \(dynamic\) has no collision geometry"):
        load_mjcf(path)


def test_bad_keyframe(scenes_dir):
    with pytest.raises(LoaderError, match="no keyframe named 'nope'"):
        load_mjcf(scenes_dir / "free_bodies.xml", keyframe="nope")
    with pytest.raises(LoaderError, match="keyframe 3 out of range"):
        load_mjcf(scenes_dir / "free_bodies.xml", keyframe=3)


def test_open_mjcf_mesh_refused_when_asked(tmp_path):
    # A single triangle fan (open) given inline.
    path = mjcf(
        tmp_path,
        '<body><freejoint/><geom type="mesh" mesh="m"/></body>',
        assets='<mesh name="m" vertex="0 0 0 1 0 0 0 1 0 0 0 1" face="0 2 1 0 1 3 0 3 2"/>',
    )
    with pytest.raises(LoaderError, match="not a closed"):
        load_mjcf(path, open_mesh="error")


def test_copied_scene_loads_from_anywhere(tmp_path, scenes_dir):
    shutil.copy(scenes_dir / "free_bodies.xml", tmp_path / "copy.xml")
    assert len(load_mjcf(tmp_path / "copy.xml").bodies) == 9


def test_jointed_mjcf_body_without_geometry(tmp_path):
    """Articulated, a hinged body with mass but no geom carries its child's joint as an inertia
    box that collides with nothing; a massless one is refused (by MuJoCo) naming it."""
    chain = (
        '<body name="upper" pos="0 0 1"><joint name="a" type="hinge"/>{inertial}'
        '<body name="lower" pos="0 0 -0.3"><joint name="b" type="hinge"/>'
        '<geom type="sphere" size="0.05"/></body></body>'
    )
    heavy = mjcf(
        tmp_path,
        chain.format(inertial='<inertial pos="0 0 0" mass="2" diaginertia="0.02 0.03 0.04"/>'),
    )
    with pytest.warns(UserWarning, match="'upper' has mass 2 kg but no collision geometry"):
        res = load_mjcf(heavy)
    assert res.names == ["upper", "lower"] and res.joint_names == ["a", "b"]
    assert res.bodies[0].geometry.meta["mass"] == pytest.approx(2.0)
    assert (0, 1) in res.contact_rules.excluded
    res.make_world().step(3)
    # A massless hinged body is MuJoCo's own refusal, naming the file and the body.
    massless = mjcf(tmp_path, chain.format(inertial=""), name="massless.xml")
    with pytest.raises(LoaderError, match="massless.xml.*\n.*Element name 'upper'"):
        load_mjcf(massless)
