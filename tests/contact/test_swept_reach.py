"""Line-search trials select their active set from the sweep's candidates that can reach d̂
there (abdsim/cpp/contact/swept_reach.h): a bound on each pair's gap along the path drops
the rest without computing their distances. The active set must still be every pair within
d̂ at the trial, with the energy of a full rebuild.

Four spheres 5 mm apart (d̂ = 2 cm) and the ground 1 cm below close in, sink and turn along
one move; trials put each body at its own fraction of it (the line search moves islands
apart, and stops some). At every trial the active pairs equal ipctk's brute force and the
ground's closed form, and the energy equals that of a term that never swept (its active set
from a broad-phase query at the trial) to 1e-12.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import trimesh

D_HAT = 0.02
GROUND = -0.11


def _assert_active_pairs_match():
    spec = importlib.util.spec_from_file_location(
        "broad_phase_brute_force", Path(__file__).with_name("test_broad_phase.py")
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.assert_active_pairs_match


def test_trials_on_the_swept_path_match_a_full_rebuild(scenes, rng):
    import ipctk

    assert_active_pairs_match = _assert_active_pairs_match()
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.1)
    geoms = [{"V": np.asarray(sphere.vertices), "F": np.asarray(sphere.faces, np.int32)}]
    q = np.stack(
        [
            scenes.q_of([0.205 * k, *rng.uniform(-0.01, 0.01, 2)], scenes.rotation(rng))
            for k in range(4)
        ]
    )
    settings = {"d_hat": D_HAT, "kappa": 1.0, "ground": True, "ground_height": GROUND}
    term = scenes.term(geoms, [0, 0, 0, 0], q, **settings)
    # Spheres 0 and 2 close in on their neighbours (4 mm of the 5 mm gaps), all sink 12 mm
    # towards the ground, sphere 3 also turns by 0.3 rad (its vertices move ~3 cm).
    dq = np.zeros_like(q)
    dq[0::2, 0] = [0.004, -0.004]
    dq[:, 2] = -0.012
    turn = scenes.rotation(np.random.default_rng(3), 0.3)
    dq[3, 3:] = (turn @ q[3, 3:].reshape(3, 3)).ravel() - q[3, 3:]
    sweep = term.body_max_steps(q, dq)
    assert sweep["scale"] == [1.0] * 4
    found = grounded = 0
    times = [np.full(4, a) for a in (0.0, 0.25, 0.5, 1.0)]
    times += [rng.uniform(0.0, 1.0, 4) for _ in range(6)]
    times += [np.array([1.0, 0.0, 1.0, 0.0]), np.array([0.0, 1.0, 0.5, 1.0])]
    bound = np.asarray(sweep["bound"])  # short of contact (CCD), each body along its move
    assert bound.min() < 1.0
    for u in times:
        t = u * bound
        trial = q + t[:, None] * dq
        value = term.value(trial)  # the line search's call: the set is built here
        fresh = scenes.term(geoms, [0, 0, 0, 0], trial, **settings)
        expected = fresh.value(trial)
        assert np.isfinite(expected) and expected > 0.0
        assert abs(value - expected) <= 1e-12 * abs(expected)
        term.update(trial)  # takes the trial's set (update after an accepted trial)
        found += assert_active_pairs_match(term, trial, D_HAT, ipctk)
        z = term.world_vertices(trial)[:, 2]
        ground = set(np.flatnonzero(z - GROUND < D_HAT).tolist())
        assert set(term.active_pairs()["point_ground"].tolist()) == ground
        grounded += len(ground)
    assert found > 100 and grounded > 10
