"""The joints' equality rows (joints/joint_rows.h) against finite differences of their values.

JointSet keeps the rows of joints whose rows are linear in q and only writes their values at
each state, and the solver checks a state with the values alone (JointSet.values): at states
away from the load pose and off the constraints, every row's gradient must still be the
derivative of its value (central differences, exact for the linear and bilinear rows up to
round-off), and rows() and values() must give the same values.
"""

from __future__ import annotations

import numpy as np
import pytest

import abdsim

from .conftest import LINK, link, rot_y

RNG_SEED = 11


def jointed_world() -> abdsim.World:
    """A hinge to the world, a prismatic joint on that moving link (bilinear rows), a weld
    and a ball joint further down: every kind of row."""
    scene = abdsim.Scene(dt=1e-3, integrator="bdf2", contact=False)
    handles = []
    top = np.zeros(3)
    for i in range(4):
        sc = link()
        T = np.eye(4)
        T[:3, :3] = rot_y(0.2 * i)
        T[:3, 3] = top
        sc.transforms = T[None]
        handles.append(scene.add(sc))
        top = top + rot_y(0.2 * i) @ np.array([0.0, 0.0, -LINK[2]])
    scene.add_joint("revolute", None, handles[0], anchor=(0, 0, 0), axis=(0, 1, 0), name="hinge")
    anchor = np.array([0.0, 0.0, -LINK[2]])
    scene.add_joint("prismatic", handles[0], handles[1], anchor=anchor, axis=(0, 0, 1), name="s")
    tip = anchor + rot_y(0.2) @ np.array([0.0, 0.0, -LINK[2]])
    scene.add_joint("fixed", handles[1], handles[2], anchor=tip, name="weld")
    scene.add_joint("ball", handles[2], handles[3], anchor=top - rot_y(0.6) @ (0, 0, -1), name="b")
    return abdsim.World(scene)


def perturbed_state(world: abdsim.World, rng: np.random.Generator) -> np.ndarray:
    """The world's state moved off its joints and off rigidity (A not a rotation)."""
    return np.ascontiguousarray(world.q).reshape(-1) + 0.05 * rng.normal(size=world.q.size)


@pytest.mark.parametrize("trial", range(3))
def test_row_gradients_are_derivatives_of_values(trial: int) -> None:
    world = jointed_world()
    joints = world._joints
    rng = np.random.default_rng(RNG_SEED + trial)
    q = perturbed_state(world, rng)
    rows = joints.rows(q)
    values = joints.values(q)
    assert len(rows) == len(values) == 6 + 11 + 12 + 3
    np.testing.assert_array_equal([r[4] for r in rows], values)
    step = 1e-6
    for body in range(world.q.shape[0]):
        for d in range(12):
            e = np.zeros_like(q)
            e[12 * body + d] = step
            fd = (joints.values(q + e) - joints.values(q - e)) / (2 * step)
            analytic = np.array(
                [
                    (r[2][d] if r[0] == body else 0.0) + (r[3][d] if r[1] == body else 0.0)
                    for r in rows
                ]
            )
            np.testing.assert_allclose(analytic, fd, rtol=0, atol=1e-8)


def test_values_are_zero_at_load_and_bad_state_raises() -> None:
    world = jointed_world()
    q0 = np.ascontiguousarray(world.q).reshape(-1)
    assert np.abs(world._joints.values(q0)).max() < 1e-12
    with pytest.raises(ValueError, match="12 entries for every body"):
        world._joints.values(q0[:-12])
    with pytest.raises(ValueError, match="12 entries for every body"):
        world._joints.rows(q0[:-1])
