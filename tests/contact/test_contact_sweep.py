"""Broad-phase queries with bounded memory (abdsim/cpp/contact/ipc_contact_sweep.cpp).

A Newton direction that moves a body far through dense meshes made the swept query behind
the step bounds collect hundreds of millions of candidate pairs (std::bad_alloc on robot
hands). The sweep now shortens the moves of the bodies that move farthest until it stays
within ``max_candidates``; a shortened move gives a conservative step bound. Here a dense
cube moves 10 m straight at another one whose facing side is 3 cm away: the first contact
is at the closed-form fraction 0.03 / 10 of the move.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import abdsim

D_HAT = 1e-3
SIDE = 0.2
GAP = 0.03
MOVE = 10.0


def _dense_cube():
    mesh = trimesh.creation.box(extents=(SIDE, SIDE, SIDE))
    for _ in range(4):  # 3072 triangles
        mesh = mesh.subdivide()
    return {"V": np.asarray(mesh.vertices, float), "F": np.asarray(mesh.faces, np.int32)}


def _scene(scenes, gap=GAP):
    """Cube 0 at the origin, cube 1 `gap` beyond its +x side, cube 2 far off to the side."""
    q = np.stack(
        [scenes.q_of([0, 0, 0]), scenes.q_of([SIDE + gap, 0, 0]), scenes.q_of([0, 5.0, 0])]
    )
    term = scenes.term([_dense_cube()], [0, 0, 0], q, d_hat=D_HAT, kappa=1.0)
    return term, q


def _move(q):
    """Cube 0 moves MOVE along +x (through cube 1), cube 2 drifts 1 mm away from everything."""
    dq = np.zeros_like(q)
    dq[0, 0] = MOVE
    dq[2, 1] = 1e-3
    return dq


def test_far_move_through_dense_cubes_stays_within_the_limit(scenes):
    term, q = _scene(scenes)
    dq = _move(q)
    first_contact = GAP / MOVE  # closed form: the facing sides are parallel

    full = term.body_max_steps(q, dq)
    assert full["scale"] == [1.0, 1.0, 1.0]
    limit = full["candidates"] // 20
    assert limit > 1000  # the unshortened sweep is large: the limit below really binds
    # ACCD keeps 10 % of the gap (ccd_target): the bound is just short of the contact.
    assert 0.85 * first_contact < full["bound"][0] <= first_contact

    term.max_candidates = limit
    capped = term.body_max_steps(q, dq)
    assert 0 < capped["candidates"] <= limit
    # Only the far mover is shortened (the move is cut by 4 at a time: 10 m -> 3.9 cm, which
    # still reaches the other cube), so its bound is the same time of impact as unshortened.
    assert capped["scale"] == [4.0**-4, 1.0, 1.0]
    assert capped["bound"][:2] == pytest.approx(full["bound"][:2], rel=1e-9)
    assert capped["bound"][2] == 1.0 and not capped["near"][2]
    # The line search's trial along the shortened move is feasible and its active set
    # comes from the kept candidates (no fresh query over the limit).
    trial = q + capped["bound"][0] * dq
    term.update(trial)
    assert np.isfinite(term.value(trial))
    gap = term.min_distance(trial, 0.005)
    assert gap == pytest.approx(GAP - capped["bound"][0] * MOVE, rel=1e-9, abs=1e-12)


def test_global_max_step_is_shortened_too(scenes):
    term, q = _scene(scenes)
    dq = _move(q)
    full = term.max_step(q, dq)
    term.max_candidates = 2000
    capped = term.max_step(q, dq)
    assert 0.2 * GAP / MOVE <= capped <= full <= GAP / MOVE


def test_overflow_at_one_configuration_is_a_solver_error(scenes):
    """Dense sides 0.5 mm apart (inside d̂): no shortening helps, a clear error says so."""
    term, q = _scene(scenes, gap=0.5e-3)
    term.max_candidates = 10
    with pytest.raises(
        abdsim.SolverError, match="more than 10 candidate pairs \\(bodies 0 and 1\\)"
    ):
        term.update(q)
    with pytest.raises(abdsim.SolverError, match="swept query found more than 10"):
        term.body_max_steps(q, np.zeros_like(q))
    with pytest.raises(ValueError, match="must be > 0"):
        term.max_candidates = 0
