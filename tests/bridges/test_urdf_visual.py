"""A URDF with only visual geometry loads from it, as MuJoCo's URDF compiler does."""

from __future__ import annotations

import pytest
import trimesh

from abdsim.bridges import load_urdf

ROBOT = """<?xml version="1.0"?>
<robot name="v">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01"
    iyz="0" izz="0.01"/></inertial>
    <visual><geometry><box size="0.2 0.1 0.1"/></geometry></visual></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01"
    iyz="0" izz="0.01"/></inertial>
    <visual><origin xyz="0 0 0.5"/><geometry><cylinder radius="0.05" length="0.4"/></geometry>
    </visual></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""


def test_visual_only_urdf_uses_its_visual_geometry_with_a_note(tmp_path):
    path = tmp_path / "v.urdf"
    path.write_text(ROBOT)
    with pytest.warns(UserWarning, match=r"no <collision> element: its <visual> geometry"):
        res = load_urdf(path)
    assert res.names == ["base", "arm"]
    base = res.bodies[0].geometry
    volume = trimesh.Trimesh(base.positions, base.triangles, process=False).volume
    assert volume == pytest.approx(0.2 * 0.1 * 0.1, rel=1e-12)
    arm = res.bodies[1].geometry
    assert arm.positions[:, 2].min() == pytest.approx(0.3, rel=1e-12)
    assert arm.positions[:, 2].max() == pytest.approx(0.7, rel=1e-12)
    assert any("<visual>" in n for n in res.notes)
