"""The coordinate θ(q) joint physics and limits act on (joints/joint_limit_coordinate.h): the
hinge angle measured in the parent's own frame, its gradient and Hessian against central
finite differences, the angle against the hinge's joint_positions() with the parent turned,
and the limit step bound never letting a limit be crossed (issue 11: tiago_pro and romeo,
whose arms rest on limits while the trunk swings, stalled Newton for hundreds of iterations
when the angle was read in world axes and the barrier's Hessian lacked θ's curvature)."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from tests.joints.conftest import chain_scene, link


def _rotation(axis, angle: float) -> np.ndarray:
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K @ K


def _moved(q: np.ndarray, body: int, R: np.ndarray, center) -> np.ndarray:
    """q with `body` turned rigidly by R about the world point `center` (A -> R A)."""
    q = q.copy()
    s = q[12 * body : 12 * body + 12]
    A, p = s[3:].reshape(3, 3), s[:3]
    c = np.asarray(center, dtype=float)
    s[:3] = R @ (p - c) + c
    s[3:] = (R @ A).reshape(-1)
    return q


def _affinely_perturbed(q: np.ndarray, bodies, rng, size=0.05) -> np.ndarray:
    """Non-rigid states: every entry of A and p of `bodies` moved by up to `size`."""
    q = q.copy()
    for b in bodies:
        q[12 * b : 12 * b + 12] += rng.uniform(-size, size, 12)
    return q


def _two_link_world(limits=None, kind="revolute"):
    """Two hanging links (angles 0.3, 0.4 at load): joint 0 to the world, joint 1 between."""
    scene, handles = chain_scene([0.3, 0.4], gravity=(0.0, 0.0, 0.0))
    if kind == "prismatic":
        scene = abdsim.Scene(dt=1e-3, contact=False, gravity=(0.0, 0.0, 0.0))
        a, b = scene.add(link()), scene.add(link())
        scene.add_joint("revolute", None, a, anchor=(0, 0, 0), axis=(0, 1, 0))
        scene.add_joint("prismatic", a, b, anchor=(0, 0, -0.5), axis=(0.3, 0.2, -1.0))
    if limits is not None:
        from dataclasses import replace

        scene._joints[1] = replace(scene._joints[1], limits=limits)
    world = abdsim.World(scene)
    return world, np.ascontiguousarray(world._core.q).reshape(-1).copy()


@pytest.mark.parametrize(("kind", "joint"), [("revolute", 0), ("revolute", 1), ("prismatic", 1)])
def test_gradient_and_hessian_match_finite_differences(kind, joint):
    world, q0 = _two_link_world(kind=kind)
    rng = np.random.default_rng(7 + joint)
    q = _affinely_perturbed(_moved(q0, 1, _rotation((0, 1, 0), 0.7), (0, 0, -1)), [0, 1], rng)
    joints = world._joints
    theta, gc, gp, H = joints.limit_coordinate(joint, q)
    child, parent = (0, -1) if joint == 0 else (1, 0)
    idx = list(range(12 * child, 12 * child + 12))
    idx += list(range(12 * parent, 12 * parent + 12)) if parent >= 0 else []
    grad = np.concatenate([gc, gp])[: len(idx)]
    eps = 1e-6
    fd_grad, fd_hess = np.zeros(len(idx)), np.zeros((len(idx), len(idx)))
    for k, i in enumerate(idx):
        up, down = q.copy(), q.copy()
        up[i] += eps
        down[i] -= eps
        t_up, gc_up, gp_up, _ = joints.limit_coordinate(joint, up)
        t_dn, gc_dn, gp_dn, _ = joints.limit_coordinate(joint, down)
        fd_grad[k] = (t_up - t_dn) / (2 * eps)
        fd_hess[:, k] = (np.concatenate([gc_up, gp_up]) - np.concatenate([gc_dn, gp_dn]))[
            : len(idx)
        ] / (2 * eps)
    assert np.abs(grad).max() > 0.1
    np.testing.assert_allclose(grad, fd_grad, rtol=0, atol=1e-8)
    Hs = np.asarray(H)[: len(idx), : len(idx)]
    assert np.abs(Hs).max() > 0.1
    np.testing.assert_allclose(Hs, Hs.T, rtol=0, atol=1e-12)
    np.testing.assert_allclose(Hs, fd_hess, rtol=0, atol=1e-7)
    if parent < 0:  # the world's half is zero
        assert not np.asarray(H)[12:, :].any() and not np.asarray(gp).any()
    # The gradient-only path (every Newton assembly and energy evaluation) combines the two
    # bilinear readings' gradients into one: the same value and gradient to round-off.
    theta_g, gc_g, gp_g, none = joints.limit_coordinate(joint, q, hessian=False)
    assert none is None and theta_g == theta
    np.testing.assert_allclose(np.concatenate([gc_g, gp_g])[: len(idx)], fd_grad, rtol=0, atol=1e-8)
    np.testing.assert_allclose(
        np.concatenate([gc_g, gp_g]), np.concatenate([gc, gp]), rtol=0, atol=1e-14
    )


def test_angle_is_the_hinge_joint_position_with_the_parent_turned():
    """Parent turned about a skew axis, child turned by φ about the hinge on top of it: the
    coordinate and joint_positions() both read φ (0 at load)."""
    world, q0 = _two_link_world()
    anchor = np.array([0.0, 0.0, -1.0]) @ _rotation((0, 1, 0), 0.3).T  # joint 1, at load
    for phi in (-2.5, -0.4, 0.0, 0.9, 3.0):
        turn = _rotation((0.3, -0.5, 0.8), 1.1)
        q = _moved(q0, 1, _rotation((0, 1, 0), phi), anchor)  # about the hinge (world y)
        q = _moved(_moved(q, 0, turn, (0.2, 0.1, 0.0)), 1, turn, (0.2, 0.1, 0.0))
        theta = world._joints.limit_coordinate(1, q)[0]
        assert theta == pytest.approx(phi, abs=1e-12)
        assert world._joints.positions(q)[1] == pytest.approx(phi, abs=1e-12)


@pytest.mark.parametrize("kind", ["revolute", "prismatic"])
def test_joint_positions_read_the_limit_coordinate_in_non_rigid_states(kind):
    """One definition of hinge and slide coordinates: on states with sheared, stretched bodies
    (where the world-axis reading differs by the strain), joint_positions() is exactly the
    coordinate the limits and joint energies act on."""
    world, q0 = _two_link_world(kind=kind)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = _affinely_perturbed(q0, (0, 1), rng)
        theta = world._joints.limit_coordinate(1, q)[0]
        assert world._joints.positions(q)[1] == theta


def test_parent_and_child_carried_together_keep_the_angle_and_the_step():
    """A Newton step that carries parent and child by the same affine map (a sub-tree
    swinging as a whole, linearised: A -> (I + t[ω]×) A) leaves the angle in the parent's
    frame unchanged, so a joint resting 1e-4 rad from its limit does not cut that step. Read
    in world axes, the stretch of the linearised turn moved the angle by 0.053 rad here, past
    the limit."""
    upper = 0.5
    world, q0 = _two_link_world(limits=(-1.0, upper))
    anchor = np.array([0.0, 0.0, -1.0]) @ _rotation((0, 1, 0), 0.3).T
    q = _moved(q0, 1, _rotation((0, 1, 0), upper - 1e-4), anchor)
    omega = np.array([0.6, -0.3, 0.5])
    W = np.array([[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]])
    dq = np.zeros_like(q)
    for b in (0, 1):
        A, p = q[12 * b + 3 : 12 * b + 12].reshape(3, 3), q[12 * b : 12 * b + 3]
        dq[12 * b : 12 * b + 3] = W @ p
        dq[12 * b + 3 : 12 * b + 12] = (W @ A).reshape(-1)
    theta0 = world._joints.limit_coordinate(1, q)[0]
    assert theta0 == pytest.approx(upper - 1e-4, abs=1e-12)
    for t in (0.25, 0.5, 1.0):
        assert world._joints.limit_coordinate(1, q + t * dq)[0] == pytest.approx(theta0, abs=1e-12)
    assert world._joint_forces.max_step(q, dq) == 1.0


@pytest.mark.parametrize("seed", range(4))
def test_step_bound_never_lets_a_limit_be_crossed(seed):
    """A step turning the child across the upper limit while the parent turns and shears:
    the bound stops it inside the limits, and no more than 1e-9 rad short of the limit."""
    lower, upper = -0.3, 0.2
    world, q0 = _two_link_world(limits=(lower, upper))
    rng = np.random.default_rng(seed)
    anchor = np.array([0.0, 0.0, -1.0]) @ _rotation((0, 1, 0), 0.3).T
    q = _affinely_perturbed(q0, [0, 1], rng, size=0.01)
    theta = world._joints.limit_coordinate(1, q)[0]
    assert lower < theta < upper
    target = _moved(q, 1, _rotation((0, 1, 0), 0.6 + 0.3 * seed), anchor)
    target = _affinely_perturbed(target, [0], rng, size=0.05)
    dq = target - q
    term = world._joint_forces
    alpha = term.max_step(q, dq)
    assert 0.0 < alpha < 1.0
    reached = world._joints.limit_coordinate(1, q + alpha * dq)[0]
    assert lower < reached < upper
    assert upper - reached < 1e-9
    assert np.isfinite(term.value(q + alpha * dq))
    assert term.value(q + 1.0 * dq) == np.inf


def test_limit_coordinate_rejects_bad_input():
    world, q = _two_link_world()
    joints = world._joints
    with pytest.raises(ValueError, match="joint out of range"):
        joints.limit_coordinate(2, q)
    with pytest.raises(ValueError, match="joint out of range"):
        joints.limit_coordinate(-1, q)
    with pytest.raises(ValueError, match="12 entries for every body"):
        joints.limit_coordinate(1, q[:12])
    ball = abdsim.Scene(dt=1e-3, contact=False)
    ball.add_joint("ball", None, ball.add(link()), anchor=(0, 0, 0))
    w = abdsim.World(ball)
    with pytest.raises(ValueError, match="revolute or prismatic"):
        w._joints.limit_coordinate(0, np.ascontiguousarray(w._core.q).reshape(-1))
