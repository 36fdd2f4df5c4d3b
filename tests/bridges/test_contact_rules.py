"""Contact filtering and per-pair friction of the loaders, against MuJoCo's own contacts."""

from __future__ import annotations

import itertools
import warnings

import mujoco
import pytest

from abdsim.bridges import load_mjcf, load_urdf
from abdsim.bridges._contact_rules import TOUCH_MARGIN, srdf_disabled_pairs

from .conftest import ROBOTS

# Every body is a sphere at the same spot, so MuJoCo's broad phase meets every pair and its
# contact list is exactly the pairs its filter lets through (the reference).
FILTER_SCENE = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1" friction="0.3"/>
    <geom name="post" type="box" size="0.05 0.05 0.05" pos="0 0 1" friction="0.2"/>
    <body name="a" pos="0 0 1"><freejoint/>
      <geom name="ga" size="0.1" friction="0.5"/>
      <body name="b"><joint type="hinge"/><geom name="gb" size="0.1" friction="0.7"/>
        <body name="c"><joint type="hinge"/><geom name="gc" size="0.1" friction="0.4"/></body>
      </body>
    </body>
    <body name="d" pos="0 0 1"><freejoint/>
      <geom name="gd" size="0.1" contype="2" conaffinity="2" friction="0.6"/></body>
    <body name="e" pos="0 0 1"><freejoint/><geom name="ge" size="0.1" friction="0.1"/></body>
    <body name="f" pos="0 0 1"><freejoint/><geom name="gf" size="0.1" friction="0.8"/></body>
  </worldbody>
  <contact>
    <exclude body1="e" body2="a"/>
    <pair geom1="gd" geom2="gf" friction="0.95 0.95 0.005 0.0001 0.0001"/>
  </contact>
</mujoco>
"""


def _mujoco_pairs(path):
    """{(geom name, geom name): μ} of MuJoCo's contacts with every sphere overlapping."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    out = {}
    for c in d.contact[: d.ncon]:
        a, b = sorted((m.geom(c.geom1).name, m.geom(c.geom2).name))
        out[(a, b)] = float(c.friction[0])
    return out


def test_mjcf_filter_and_friction_match_mujoco_contacts(tmp_path):
    path = tmp_path / "filter.xml"
    path.write_text(FILTER_SCENE)
    res = load_mjcf(path, kinematic=True)
    rules = res.contact_rules
    reference = _mujoco_pairs(path)
    names = {b.geoms[0]: i for i, b in enumerate(res.bodies)}
    checked = 0
    for ga, gb in itertools.combinations(sorted(names), 2):
        i, j = sorted((names[ga], names[gb]))
        if res.bodies[i].kind == "fixed" and res.bodies[j].kind == "fixed":
            continue
        expected = reference.get(tuple(sorted((ga, gb))))
        collide = (i, j) not in rules.excluded
        assert collide == (expected is not None), (ga, gb)
        if expected is not None:
            assert rules.friction[(i, j)] == pytest.approx(expected, abs=1e-12), (ga, gb)
        checked += 1
    assert checked == 21  # 6 moving spheres with each other (15) and the post (6)
    # The hand-derived rules, spelled out: parent-child (a-b, b-c) and the exclude (a-e) are
    # filtered, a-c (grandparent) collides; d (contype 2) meets only f, through the <pair>.
    i = {n: res.index(n) for n in "abcdef"}
    assert (min(i["a"], i["b"]), max(i["a"], i["b"])) in rules.excluded
    assert (min(i["a"], i["c"]), max(i["a"], i["c"])) not in rules.excluded
    assert (min(i["a"], i["e"]), max(i["a"], i["e"])) in rules.excluded
    assert rules.friction[(min(i["d"], i["f"]), max(i["d"], i["f"]))] == pytest.approx(0.95)
    # The ground row: d (contype 2) never touches the floor (contype 1), the others do with
    # MuJoCo's max rule.
    assert rules.ground_excluded == {i["d"]}
    assert rules.ground_friction[i["a"]] == pytest.approx(0.5)
    assert rules.ground_friction[i["e"]] == pytest.approx(0.3)


def test_contact_table_receives_the_rules(tmp_path):
    path = tmp_path / "filter.xml"
    path.write_text(FILTER_SCENE)
    res = load_mjcf(path, kinematic=True)
    scene = res.build_scene()
    i = {n: res.index(n) for n in "abdf"}
    assert scene.contact_table.get(i["a"], i["b"]) == (False, None)
    assert scene.contact_table.get(i["d"], i["f"]) == (True, pytest.approx(0.95))
    assert scene.contact_table.get(i["d"], "ground") == (False, None)
    assert scene.contact_elements().tolist() == list(range(len(res.bodies)))


def test_fish_and_humanoid_cmu_load_because_of_the_parent_filter():
    dm_control = pytest.importorskip("dm_control", reason="dm_control is not installed")
    from pathlib import Path

    suite = Path(dm_control.__file__).parent / "suite"
    for name in ("fish.xml", "humanoid_CMU.xml"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = load_mjcf(suite / name, kinematic=True)
        world = res.make_world()  # raised "bodies ... intersect" before the filter
        world.step(1)
        assert world.diagnostics.min_contact_distance > 0


URDF_CHAIN = """<?xml version="1.0"?>
<robot name="chain">
  {links}
  <joint name="j1" type="revolute"><parent link="l0"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""
LINK = """<link name="{n}"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0"
  iyy="0.01" iyz="0" izz="0.01"/></inertial><collision><origin xyz="{x} 0 0"/>
  <geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>"""


def _chain(tmp_path, xs):
    links = "".join(LINK.format(n=f"l{k}", x=x) for k, x in enumerate(xs))
    path = tmp_path / "chain.urdf"
    path.write_text(URDF_CHAIN.format(links=links))
    return path


def test_urdf_adjacent_links_and_srdf_pairs_never_collide(tmp_path):
    path = _chain(tmp_path, [0.0, 1.0, 2.0])  # far apart: only the joint rule applies
    res = load_urdf(path)
    i = [res.index(f"l{k}") for k in range(3)]
    assert res.contact_rules.excluded == {tuple(sorted((i[0], i[1]))), tuple(sorted((i[1], i[2])))}
    srdf = tmp_path / "chain.srdf"
    srdf.write_text(
        '<robot name="chain"><disable_collisions link1="l0" link2="l2" reason="Never"/></robot>'
    )
    assert srdf_disabled_pairs(srdf) == [("l0", "l2")]
    res = load_urdf(path, srdf=srdf)
    assert tuple(sorted((i[0], i[2]))) in res.contact_rules.excluded


def test_floating_links_touching_at_load_are_excluded_with_a_note(tmp_path):
    # l0 (floating, dynamic) and l2 (its grandchild) are 1 cm apart... overlapping: excluded,
    # with a note; l1 is far away and only the joint rule applies to it.
    path = _chain(tmp_path, [0.0, 1.0, 0.09])
    with pytest.warns(UserWarning, match=r"touch .* never collide"):
        res = load_urdf(path, floating_base=True)
    i = [res.index(f"l{k}") for k in range(3)]
    assert tuple(sorted((i[0], i[2]))) in res.contact_rules.excluded
    assert any("touch" in n and "'l2'" in n for n in res.notes)
    # A gap larger than the margin keeps the pair colliding.
    res = load_urdf(_chain(tmp_path, [0.0, 1.0, 0.1 + 2 * TOUCH_MARGIN]), floating_base=True)
    assert tuple(sorted((i[0], i[2]))) not in res.contact_rules.excluded


def test_floating_legged_robots_load_and_step():
    """solo12 took 33-45 s a step with 14,739 self-contact pairs; talos was refused."""
    if ROBOTS is None:
        pytest.skip("example-robot-data is not installed")
    for description, filename in [
        ("solo_description", "solo12.urdf"),
        ("talos_data", "talos_reduced.urdf"),
        ("anymal_b_simple_description", "anymal.urdf"),
    ]:
        path = next((ROBOTS / description).glob(f"*/{filename}"))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = load_urdf(path, floating_base=True)
        world = res.make_world()
        for _ in range(5):
            world.step(1)
            assert world.diagnostics.min_contact_distance > 0
        assert sum(world.diagnostics.contact_pairs.values()) < 1000, filename
