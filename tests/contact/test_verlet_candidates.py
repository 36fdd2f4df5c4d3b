"""Broad-phase candidates reused while vertices stay near the list's centre (a Verlet list,
abdsim/cpp/contact/verlet_candidates.h) are still every pair within d̂.

One contact term follows a sequence of small moves (each vertex within the list's slack of
where the list was built, so the list is filtered, not rebuilt) and larger ones (rebuilt):
at every configuration its active pairs must equal an independent brute force (ipctk's exact
distances, test_broad_phase.assert_active_pairs_match), and its CCD bound along a move must
equal the one of a term that has never seen the earlier configurations.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import trimesh

D_HAT = 0.02  # the list's slack is 2 d̂: 4 cm


def _broad_phase_tests():
    spec = importlib.util.spec_from_file_location(
        "broad_phase_brute_force", Path(__file__).with_name("test_broad_phase.py")
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _scene(scenes, rng):
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.1)
    geoms = [{"V": np.asarray(sphere.vertices), "F": np.asarray(sphere.faces, np.int32)}]
    q = np.stack(
        [
            scenes.q_of([0.205 * k, *rng.uniform(-0.01, 0.01, 2)], scenes.rotation(rng))
            for k in range(4)
        ]
    )
    return geoms, q


def test_reused_candidates_match_brute_force(scenes, rng):
    import ipctk

    assert_active_pairs_match = _broad_phase_tests().assert_active_pairs_match
    geoms, q = _scene(scenes, rng)
    term = scenes.term(geoms, [0, 0, 0, 0], q, d_hat=D_HAT, kappa=1.0)
    found = 0
    for step in range(12):
        # Mostly moves of a few mm (the list is kept), every fourth one of 6 cm (rebuilt).
        size = 0.06 if step % 4 == 3 else 0.004
        move = np.zeros_like(q)
        move[:, 1:3] = rng.uniform(-size, size, (len(q), 2))
        move[:, 0] = rng.uniform(-0.001, 0.001, len(q))  # gaps along x stay >= 3 mm
        trial = q + move  # from the start: small moves stay within the slack of each other
        term.update(trial)
        found += assert_active_pairs_match(term, trial, D_HAT, ipctk)
    assert found > 50


def test_ccd_bound_does_not_depend_on_earlier_queries(scenes, rng):
    geoms, q = _scene(scenes, rng)
    term = scenes.term(geoms, [0, 0, 0, 0], q, d_hat=D_HAT, kappa=1.0)
    # The spheres close in on each other along x: 2 cm for the odd ones, in steps.
    dq = np.zeros_like(q)
    dq[1::2, 0] = -0.02
    bounds = []
    for t in np.linspace(0.0, 0.5, 6):
        x = q + t * dq
        fresh = scenes.term(geoms, [0, 0, 0, 0], x, d_hat=D_HAT, kappa=1.0)
        bound = term.max_step(x, dq)
        assert bound == fresh.max_step(x, dq)
        bounds.append(bound)
    # The gaps (5 mm) close within the move: the bound is a real one.
    assert min(bounds) < 1.0


def _update_and_check(term, trial, ground):
    """term.update(trial), then its active pairs against ipctk's brute force and the ground's
    closed form; returns how many pairs and ground vertices were checked."""
    import ipctk

    term.update(trial)
    found = _broad_phase_tests().assert_active_pairs_match(term, trial, D_HAT, ipctk)
    z = term.world_vertices(trial)[:, 2]
    expected = set(np.flatnonzero(z - ground < D_HAT).tolist())
    assert set(term.active_pairs()["point_ground"].tolist()) == expected
    return found, len(expected)


def test_reused_candidates_under_turns_match_brute_force(scenes, rng):
    """Two spheres keep turning (their vertices leave the list's slack: only their pairs are
    queried again, verlet_candidates.h) while the others and the ground stay: the active
    pairs equal ipctk's brute force and the ground's closed form at every step, and CCD bounds
    those of a term that has never seen the earlier configurations."""

    geoms, q = _scene(scenes, rng)
    ground = -0.11  # 1 cm below the spheres' lowest points: within d̂
    settings = {"d_hat": D_HAT, "kappa": 1.0, "ground": True, "ground_height": ground}
    term = scenes.term(geoms, [0, 0, 0, 0], q, **settings)
    found = grounded = 0
    for step in range(1, 9):
        trial = q.copy()
        for k in (1, 3):  # 0.5 rad a step about their centres: vertices move up to 5 cm
            turn = scenes.rotation(np.random.default_rng(k), 0.5 * step)
            A = turn @ q[k, 3:].reshape(3, 3)
            trial[k] = scenes.q_of(q[k, :3], A)
        for k in (0, 2):  # a few mm: within the slack of where the list was built
            trial[k, 1:3] += rng.uniform(-0.004, 0.004, 2)
        pairs, on_ground = _update_and_check(term, trial, ground)
        found += pairs
        grounded += on_ground
        dq = np.zeros_like(q)
        dq[0::2, 0] = [0.004, -0.004]  # spheres 0 and 2 close in on their turning neighbours
        dq[:, 2] = -0.012  # and sink towards the ground
        fresh = scenes.term(geoms, [0, 0, 0, 0], trial, **settings)
        assert term.max_step(trial, dq) == fresh.max_step(trial, dq)
    assert found > 50 and grounded > 8


def test_far_moves_of_some_bodies_match_brute_force(scenes, rng):
    """Spheres 1 and 3 jump 10 cm a step (longer than twice the slack: no centre covers them,
    their pairs come from a direct query for them alone) while 0 and 2 move a few mm (their
    pairs stay listed): active pairs equal ipctk's brute force and the ground's closed form,
    and swept CCD bounds with far and near moves mixed equal those of a fresh term."""

    geoms, q = _scene(scenes, rng)
    ground = -0.11
    settings = {"d_hat": D_HAT, "kappa": 1.0, "ground": True, "ground_height": ground}
    term = scenes.term(geoms, [0, 0, 0, 0], q, **settings)
    found = grounded = 0
    bounds = []
    for step in range(1, 9):
        trial = q.copy()
        trial[1::2, 2] += 0.1 * (step % 2)  # up off the ground and back
        trial[1::2, 1] += rng.uniform(-0.004, 0.004, 2)
        trial[0::2, 1:3] += rng.uniform(-0.004, 0.004, (2, 2))
        pairs, on_ground = _update_and_check(term, trial, ground)
        found += pairs
        grounded += on_ground
        dq = np.zeros_like(q)
        dq[1::2, 2] = 0.1 if step % 2 == 0 else -0.1  # far: 10 cm
        dq[0::2, 0] = [0.004, -0.004]  # near: close in on the far ones' paths
        dq[0::2, 2] = -0.012
        fresh = scenes.term(geoms, [0, 0, 0, 0], trial, **settings)
        bound = term.max_step(trial, dq)
        assert bound == fresh.max_step(trial, dq)
        bounds.append(bound)
    assert found > 20 and grounded > 0
    assert min(bounds) < 1.0
