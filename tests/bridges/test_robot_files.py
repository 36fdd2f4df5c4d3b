"""Every real robot file loads as a dynamic articulation (the loaders' default), builds a
World and steps without intersection (issue 11).

Walks every URDF of the installed example-robot-data and every dm_control suite XML (the
``dm_control`` package of the test extra; skipped with a message when missing). A file that
Pinocchio itself rejects, or that has no geometry at all, must fail with a LoaderError naming
the file. Every dm_control suite file loads dynamic (bodies on several joints, planar roots and
two- or three-hinge hips, as chains of joint frames). A URDF loads with the SRDF
example-robot-data ships for it (its ``disable_collisions`` pairs never collide, as in MoveIt
and Pinocchio's collision setup). The steps' gaps are abdsim's; at the end coal checks,
independently, that no pair of bodies that may touch (one of them moving) intersects.

Files whose load takes long (dense meshes) are the heavy part: run with ABDSIM_HEAVY_TESTS=1.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
import pytest

from abdsim.bridges import LoaderError, load_mjcf, load_urdf

from .conftest import ROBOTS

STEPS = 100
HEAVY = os.environ.get("ABDSIM_HEAVY_TESTS") == "1"
#: The default (CI) walk: URDFs that load and step 100 dynamic steps in about a second or
#: less here; every other file walks with ABDSIM_HEAVY_TESTS=1 (dense meshes, self-contact of
#: hands and humanoids take seconds to minutes).
LIGHT_URDFS = {
    "a1.urdf",
    "allegro_left_hand.urdf",
    "anymal.urdf",
    "b1.urdf",
    "bolt.urdf",
    "double_pendulum.urdf",
    "double_pendulum_continuous.urdf",
    "finger_edu.urdf",
    "go1.urdf",
    "hyq_no_sensors.urdf",
    "panda.urdf",
    "quadrotor_base.urdf",
    "simple_humanoid.urdf",
    "talos_left_arm.urdf",
    "ur3.urdf",
    "ur5_robot.urdf",
}
#: dm_control files whose load takes long (dense meshes).
HEAVY_XMLS = {"dog.xml"}
#: URDFs with a link smaller than 4 d_hat (tiago's 2 mm finger boxes): the World refuses the
#: default d_hat naming the body, and they walk with a smaller one.
SMALL_PARTS = {"tiago.urdf": 5e-4, "tiago_dual.urdf": 5e-4}
#: Files that are not loadable robots, with what the error must say.
REJECTED = {
    "ur3.urdf": "has no <link>",  # an empty xacro leftover: Pinocchio rejects it too
}


def _urdfs() -> list[Path]:
    return sorted(ROBOTS.glob("**/*.urdf")) if ROBOTS is not None else []


def _srdf(urdf: Path) -> Path | None:
    """The SRDF shipped next to a URDF: ``../srdf/<name>.srdf`` whose name is the longest
    prefix of the URDF's (``talos_reduced_box.urdf`` -> ``talos.srdf``), or None."""
    folder = urdf.parent.parent / "srdf"
    found = [s for s in folder.glob("*.srdf") if urdf.stem.startswith(s.stem)]
    return max(found, key=lambda s: len(s.stem)) if found else None


def _suite_xmls() -> list[Path]:
    try:
        import dm_control
    except ImportError:
        return []
    return sorted((Path(dm_control.__file__).parent / "suite").glob("*.xml"))


def _id(p: Path) -> str:
    return f"{p.parent.parent.name}/{p.name}"


def _params(paths: list[Path]) -> list:
    def marks(p: Path) -> list:
        heavy = p.name in HEAVY_XMLS if p.suffix == ".xml" else p.name not in LIGHT_URDFS
        out = [pytest.mark.skipif(not HEAVY, reason="heavy file: set ABDSIM_HEAVY_TESTS=1")]
        return out if heavy else []

    return [pytest.param(p, id=_id(p), marks=marks(p)) for p in paths]


def _simulate(result) -> float:
    """STEPS steps; the smallest gap abdsim saw (inf: no contact pair came near)."""
    d_hat = SMALL_PARTS.get(result.source.name)
    if d_hat is not None:
        with pytest.raises(ValueError, match="is not small against body .* use a d_hat"):
            result.make_world()
    world = result.make_world(**({"d_hat": d_hat} if d_hat else {}))
    gap = np.inf
    for _ in range(STEPS):
        world.step(1)
        gap = min(gap, world.diagnostics.min_contact_distance)
    _assert_no_intersection(result, world)
    return gap


def _assert_no_intersection(result, world) -> None:
    """coal: no pair that may touch (at least one body moving) intersects at the end."""
    import coal

    moving = [i for i, b in enumerate(result.bodies) if b.kind == "dynamic"]
    if not moving:
        return
    rules = result.contact_rules
    T = np.asarray(world.transforms())
    models = {}

    def model(i):
        # World vertices of the affine map (not a rigid pose), at an identity placement.
        if i not in models:
            g = result.bodies[i].geometry
            V = np.asarray(g.positions) @ T[i][:3, :3].T + T[i][:3, 3]
            m = coal.BVHModelOBBRSS()
            m.beginModel(len(g.triangles), len(V))
            m.addVertices(np.ascontiguousarray(V, dtype=float))
            m.addTriangles(np.ascontiguousarray(g.triangles, dtype=np.int64))
            m.endModel()
            models[i] = m
        return models[i]

    for i in moving:
        for j in range(len(result.bodies)):
            if j == i or (j in moving and j < i):
                continue
            if rules is not None and (min(i, j), max(i, j)) in rules.excluded:
                continue
            req, res = coal.CollisionRequest(), coal.CollisionResult()
            if coal.collide(model(i), coal.Transform3s(), model(j), coal.Transform3s(), req, res):
                pytest.fail(
                    f"{result.source.name}: bodies {result.bodies[i].name!r} and "
                    f"{result.bodies[j].name!r} intersect after {STEPS} steps"
                )


@pytest.mark.parametrize("path", _params(_urdfs()))
def test_every_example_robot_urdf_loads_and_steps(path):
    if ROBOTS is None:
        pytest.skip("example-robot-data is not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if path.name in REJECTED:
            with pytest.raises(LoaderError, match=REJECTED[path.name]) as err:
                load_urdf(path)
            assert path.name in str(err.value)
            return
        result = load_urdf(path, srdf=_srdf(path))
    assert len(result.bodies) >= 1
    assert all(b.kind != "kinematic" for b in result.bodies)
    assert len(result.scene.joints) == len(result.joint_names)
    assert _simulate(result) > 0


@pytest.mark.skipif(not HEAVY, reason="heavy: set ABDSIM_HEAVY_TESTS=1")
@pytest.mark.parametrize("path", [pytest.param(p, id=_id(p)) for p in _urdfs()])
def test_every_example_robot_urdf_loads_floating_and_steps(path):
    """With a free-flyer root the trunk is dynamic: links touching it must not block the load."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if path.name in REJECTED:
            with pytest.raises(LoaderError, match=path.name.replace(".", r"\.")):
                load_urdf(path, floating_base=True)
            return
        result = load_urdf(path, floating_base=True, srdf=_srdf(path))
    assert _simulate(result) > 0


@pytest.mark.parametrize("path", _params(_suite_xmls()))
def test_every_dm_control_suite_xml_loads_and_steps(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = load_mjcf(path)
    assert result.articulated and all(b.kind != "kinematic" for b in result.bodies)
    # Joint frames add bodies, never joints: one abdsim joint per MuJoCo hinge/slide/ball.
    m = result.model
    assert result.joint_names == [m.joint(j).name for j in range(m.njnt) if m.jnt_type[j] != 0]
    assert [j.name for j in result.scene.joints] == result.joint_names  # lqr.xml has none
    assert _simulate(result) > 0


def test_dm_control_suite_is_present():
    """Says why the suite walk found no file, instead of passing silently."""
    if not _suite_xmls():
        pytest.skip("dm_control is not installed (pip install dm_control): suite not walked")
    assert len(_suite_xmls()) >= 19
