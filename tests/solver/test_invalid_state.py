"""Invalid states are refused where they enter (World, set_state, targets, step count)."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim


def _box(size=0.2, at=(0.0, 0.0, 0.0), scale=1.0):
    sc = abdsim.geometry.box(size)
    abdsim.AffineBodyConstitution().apply_to(sc, 1e8)
    T = np.eye(4)
    T[:3, :3] *= scale
    T[:3, 3] = at
    sc.transforms = T
    return sc


def _world(*bodies, **settings):
    scene = abdsim.Scene(**settings)
    for b in bodies:
        scene.add(b)
    return abdsim.World(scene)


def test_nan_rest_position_written_after_apply_to_is_refused():
    sc = _box()
    sc.positions[3, 1] = np.nan
    scene = abdsim.Scene()
    scene.add(sc)
    with pytest.raises(ValueError, match="geometry 0: rest position of vertex 3"):
        abdsim.World(scene)


@pytest.mark.parametrize("bad", [np.inf, np.nan, 0.0, -0.01])
def test_bad_thickness_is_refused(bad):
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    sc = abdsim.geometry.triangle_mesh(v, np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match="thickness"):
        abdsim.AffineBodyShell().apply_to(sc, 1e8, thickness=bad)


@pytest.mark.parametrize(
    ("A", "match"),
    [
        (np.diag([1.0, 1.0, -1.0]), "det -1 <= 0"),
        (np.diag([1.0, 1.0, 0.0]), "degenerate"),
        (np.diag([1.0, 1e-9, 1.0]), "degenerate"),
    ],
)
def test_mirror_and_degenerate_transforms_are_refused_everywhere(A, match):
    T = np.eye(4)
    T[:3, :3] = A
    sc = abdsim.geometry.box(0.2)
    with pytest.raises(ValueError, match=match):
        sc.transforms = T
    world = _world(_box(), gravity=(0, 0, 0))
    with pytest.raises(ValueError, match=match):
        world.set_state(T[None])
    with pytest.raises(ValueError, match=match):
        world.set_kinematic_target(0, T)
    # transforms edited in place after add() are checked again by World()
    sc = _box()
    scene = abdsim.Scene()
    scene.add(sc)
    sc.instances["transform"][0, :3, :3] = A
    with pytest.raises(ValueError, match=match):
        abdsim.World(scene)


def test_set_state_refuses_overlapping_bodies_and_keeps_the_state():
    world = _world(_box(at=(0, 0, 0)), _box(at=(1, 0, 0)), gravity=(0, 0, 0))
    before = world.q
    T = world.transforms()
    T[1, 0, 3] = 0.1  # half inside body 0
    with pytest.raises(ValueError, match="set_state: invalid configuration for contact"):
        world.set_state(T)
    np.testing.assert_array_equal(world.q, before)


def test_a_body_nested_inside_a_closed_solid_is_refused():
    big, small = _box(1.0), _box(0.1, at=(0.1, 0.05, 0.0))
    with pytest.raises(ValueError, match="body 1 lies inside the closed solid of body 0"):
        _world(big, small)
    world = _world(_box(1.0), _box(0.1, at=(2.0, 0, 0)), gravity=(0, 0, 0))
    T = world.transforms()
    T[1, :3, 3] = (0.2, -0.1, 0.3)
    with pytest.raises(ValueError, match="body 1 lies inside the closed solid of body 0"):
        world.set_state(T)
    # the same pair side by side is fine; a disabled contact pair may nest
    _world(_box(1.0), _box(0.1, at=(0.6, 0, 0)))
    scene = abdsim.Scene()
    scene.add(_box(1.0), contact_element=1)
    scene.add(_box(0.1), contact_element=2)
    scene.contact_table.set(1, 2, enabled=False)
    abdsim.World(scene)


@pytest.mark.parametrize("n", [np.nan, np.inf, 1.5, 0, -1, True, "2"])
def test_bad_step_counts_are_refused(n):
    world = _world(_box())
    with pytest.raises(ValueError, match="step count must be a positive integer"):
        world.step(n)
    assert world.step_count == 0


def test_large_initial_scale_relaxes_without_inverting():
    # A box scaled 10x: the shape energy pulls it back to a rotation. It used to overshoot
    # to det A = -1 in one step.
    world = _world(_box(scale=10.0), gravity=(0, 0, 0))
    for _ in range(20):
        world.step()
        A = world.q[0, 3:].reshape(3, 3)
        assert np.linalg.det(A) > 0
    A = world.q[0, 3:].reshape(3, 3)
    np.testing.assert_allclose(A @ A.T, np.eye(3), atol=0.05)


def test_a_kinematic_body_cannot_crush_a_dynamic_one():
    # A kinematic slab driven down onto a box resting on the ground: the box may not be
    # flattened (det A -> 0); the step fails with a message naming the box.
    scene = abdsim.Scene(gravity=(0, 0, 0), dt=0.01)
    scene.add_ground(0.0)
    box = scene.add(_box(0.2, at=(0, 0, 0.1 + 2e-3)))
    slab = scene.add(_box(0.5, at=(0, 0, 0.2 + 0.25 + 4e-3)), kinematic=True)
    world = abdsim.World(scene)
    z0 = world.q[slab.body(), 2]
    with pytest.raises(abdsim.SolverError, match="body 0 .* would (collapse|invert)"):
        for k in range(1, 40):
            T = np.eye(4)
            T[2, 3] = z0 - 0.01 * k
            world.set_kinematic_target(slab.body(), T)
            world.step()
            assert np.linalg.det(world.q[box.body(), 3:].reshape(3, 3)) >= 1e-2
    assert np.linalg.det(world.q[box.body(), 3:].reshape(3, 3)) >= 1e-2


def test_vertices_removed_after_apply_to_are_refused_by_world():
    sc = _box()
    sc.vertices.resize(3)  # the 12 triangles now refer to vertices 3..7 that are gone
    scene = abdsim.Scene()
    scene.add(sc)
    with pytest.raises(
        ValueError, match=r"geometry 0: triangle \d+ refers to vertex .* 3 vertices"
    ):
        abdsim.World(scene)
