"""URDF structure errors name what is wrong and where (Pinocchio only says "does not contain
a valid URDF model"); loading is linear in the number of links; the loader's kinematics
equal Pinocchio's."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

from abdsim.bridges import LoaderError, load_urdf
from abdsim.bridges.urdf import joint_kinematics

BOX = '<collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision>'
INERTIAL = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
)


def link(name: str) -> str:
    return f'<link name="{name}">{INERTIAL}{BOX}</link>'


def joint(name, parent, child, kind="revolute", axis="0 1 0", origin='xyz="0 0 0.1"', limit=True):
    lim = '<limit lower="-1" upper="1" effort="1" velocity="1"/>' if limit else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin {origin}/><axis xyz="{axis}"/>{lim}</joint>'
    )


def chain_urdf(n: int) -> str:
    parts = [link(f"l{i}") for i in range(n)]
    parts += [joint(f"j{i}", f"l{i - 1}", f"l{i}") for i in range(1, n)]
    return f'<robot name="chain">{"".join(parts)}</robot>'


def write(tmp_path, body: str):
    path = tmp_path / "r.urdf"
    path.write_text(f'<?xml version="1.0"?>\n<robot name="r">{body}</robot>')
    return path


@pytest.mark.parametrize(
    ("body", "match"),
    [
        (link("a") + joint("j", "a", "ghost"), r"joint 'j': child link 'ghost' does not exist"),
        (link("a") + link("b") + joint("j", "a", "b", kind="hinge"), r"joint 'j': type 'hinge'"),
        (link("a") + link("b") + joint("j", "a", "b", limit=False), "needs a <limit>"),
        (link("a") + link("b") + joint("j", "a", "b", axis="0 0 0"), r"'j': <axis xyz> is zero"),
        (link("a") + link("b") + joint("j", "a", "b", origin='xyz="0 nan 0"'), "3 finite"),
        (link("a") + link("b") + joint("j", "a", "b", origin='rpy="0 0"'), "3 finite"),
        (link("a") + link("a"), "two links are named 'a'"),
        (link("a") + link("b"), r"a forest; root links \(no parent joint\): \['a', 'b'\]"),
        (
            link("a") + link("b") + link("c") + joint("j1", "a", "b") + joint("j2", "c", "b"),
            "link 'b' is already the child of link 'a'",
        ),
        (
            link("a") + link("b") + link("c") + joint("j1", "b", "c") + joint("j2", "c", "b"),
            r"links \['b', 'c'\] are in a cycle",
        ),
        (link("a") + '<joint name="j" type="fixed"><child link="a"/></joint>', "no <parent"),
    ],
    ids=[
        "missing-child",
        "bad-type",
        "no-limit",
        "zero-axis",
        "nan-origin",
        "short-rpy",
        "duplicate-link",
        "forest",
        "two-parents",
        "cycle",
        "no-parent",
    ],  # fmt: skip
)
def test_structure_errors_name_the_element(tmp_path, body, match):
    with pytest.raises(LoaderError, match=match):
        load_urdf(write(tmp_path, body))


@pytest.mark.parametrize("floating_base", [False, True])
def test_joint_kinematics_equal_pinocchio_forward_kinematics(robot_urdf, floating_base):
    path = robot_urdf("panda_description", "panda.urdf")
    model = (
        pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        if floating_base
        else pin.buildModelFromUrdf(str(path))
    )
    rng = np.random.default_rng(5)
    np.random.seed(5)
    lo = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -1.0)
    hi = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, 1.0)
    q = pin.randomConfiguration(model, np.maximum(lo, -3), np.minimum(hi, 3))
    v = rng.normal(size=model.nv)
    data = model.createData()
    pin.forwardKinematics(model, data, q, v)
    kin = joint_kinematics(pin, model, q, v)
    for j in range(model.njoints):
        np.testing.assert_allclose(kin.oMi[j].homogeneous, data.oMi[j].homogeneous, atol=1e-12)
        np.testing.assert_allclose(kin.v[j].vector, data.v[j].vector, atol=1e-12)
        if j > 0:
            np.testing.assert_allclose(kin.S[j], np.array(data.joints[j].S), atol=1e-15)


@pytest.mark.slow
def test_a_2000_link_chain_loads_with_memory_linear_in_the_links(tmp_path):
    """pinocchio.Data (dense nv x nv buffers) took 4.1 GB for 400 joints and raised an empty
    MemoryError at 2,000; the loader no longer builds one. Run in a fresh interpreter so its
    peak memory (maxrss) is this load's alone."""
    path = tmp_path / "chain.urdf"
    path.write_text(chain_urdf(2000))
    script = (
        "import json, resource, sys, numpy as np\n"
        "from abdsim.bridges import load_urdf\n"
        "r = load_urdf(sys.argv[1])\n"
        "z = [b.transform[2, 3] for b in r.bodies]\n"
        "print(json.dumps({'bodies': len(r.bodies), 'parents': [b.parent for b in r.bodies],"
        " 'z': z, 'rss_mb': resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))\n"
    )
    out = subprocess.run(
        [sys.executable, "-P", "-c", script, str(path)], capture_output=True, text=True, check=True
    )
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["bodies"] == 2000
    assert result["parents"] == [None] + list(range(1999))
    # joint i sits 0.1 m above joint i - 1 at the neutral configuration
    np.testing.assert_allclose(result["z"], 0.1 * np.arange(2000), atol=1e-9)
    assert result["rss_mb"] < 1500, f"peak memory {result['rss_mb']:.0f} MB"
