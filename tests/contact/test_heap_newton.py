"""A heap of boxes landing and coming to rest (issue 12's scene, 20 boxes): Newton starts each
island at its warm guess (the last step's contact forces carried over, World::warm_guess), so
the resting heap takes one or two Newton iterations a step (steps 150-199: median 1, at most
2; steps 100-149 had median 1, at most 3, before majorised friction steps changed the
trajectory, and median 12, 8-40, when every island started where it was), without
intersections (coal)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import abdsim

EXTENTS = (0.10, 0.08, 0.06)
SPACING = 0.15  # > the boxes' diameter: no overlap at the start, any rotation


def heap(n: int = 20, layers: int = 5, seed: int = 0) -> abdsim.World:
    """n boxes, randomly rotated, in `layers` layers on a grid, every other layer shifted by
    half a cell so that boxes land on boxes (benchmarks/contact_heap.py's heap)."""
    rng = np.random.default_rng(seed)
    per_layer = n // layers
    side = int(np.ceil(np.sqrt(per_layer)))
    k = np.arange(n)
    layer, slot = k // per_layer, k % per_layer
    shift = 0.5 * SPACING * (layer % 2)
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    R = np.stack(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    ).transpose(2, 0, 1)
    scene = abdsim.Scene(dt=0.01, friction=0.5, history_limit=0)
    scene.add_ground(0.0)
    boxes = abdsim.geometry.box(EXTENTS)
    boxes.instances.resize(n)
    T = np.tile(np.eye(4), (n, 1, 1))
    T[:, :3, :3] = R
    T[:, 0, 3] = SPACING * (slot % side) + shift
    T[:, 1, 3] = SPACING * (slot // side) + shift
    T[:, 2, 3] = 0.08 + SPACING * layer
    boxes.transforms = T
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(boxes, kappa=1e8, mass_density=1e3)
    scene.add(boxes)
    return abdsim.World(scene)


def test_a_resting_heap_takes_one_or_two_newton_iterations_a_step(wc):
    world = heap()
    iterations = []
    # Steps 150-199: in this trajectory a box still topples at step 100 (0.32 m/s); the heap
    # is at rest from about step 140 (its fastest vertex below 2e-3 m/s).
    for _ in range(200):
        d = world.step()
        assert d.min_contact_distance > 0
        iterations.append(d.newton_iterations)
    resting = np.asarray(iterations[150:])
    assert np.median(resting) <= 2 and resting.max() <= 4
    assert np.abs(world.velocities()[:, :3, 3]).max() < 1e-2  # the heap has come to rest
    hits, d_min, low = wc.coal_check(world)
    assert hits == 0 and d_min > 0 and low > 0


def test_a_step_whose_refined_pieces_still_cross_is_accepted_at_eighths(wc):
    """Heap of 50 boxes (seed 5), step 17: the first landing step's straight line crosses a
    contact surface, and so does the whole step's line after pieces of every refinement (a box
    turning round another's edge). Refinement everywhere stops at pieces of dt / 8: 0.20 s CPU;
    it went on to 512 pieces of dt / 512, 1.35 s, whose whole line still crossed and was
    accepted unchecked. The step says so, and the state it reports is free of intersections
    (coal)."""
    world = heap(n=50, seed=5)
    for _ in range(17):
        assert world.step().discarded_newton_iterations == 0
    d = world.step()
    assert d.substeps == 8
    assert "still crosses after pieces of dt / 8 everywhere" in d.substep_reason
    # The rejected whole step and the rounds of halves and quarters were thrown away: part
    # of the step's iterations and time, not all of them (the eighths were kept).
    assert 0 < d.discarded_newton_iterations < d.newton_iterations
    assert 0 < d.discarded_time < d.wall_time
    assert d.min_contact_distance > 0
    hits, d_min, low = wc.coal_check(world)
    assert hits == 0 and d_min > 0 and low > 0


def test_a_landing_heap_takes_majorised_friction_steps_after_a_halving(wc):
    """The heap landing (20 boxes, steps 0-59, seeds 0 and 1): after a line search that had to
    halve a step, the next Newton iteration takes friction's majorising model
    (EnergyTerm::set_majorizing_model), whose steps cannot overshoot a stopping slide.
    1,681 and 1,682 Newton iterations; 2,574 and 2,694 with the exact model throughout. No
    intersections (coal)."""
    for seed in (0, 1):
        world = heap(seed=seed)
        iterations = 0
        for _ in range(60):
            d = world.step()
            assert d.min_contact_distance > 0
            iterations += d.newton_iterations
        assert iterations <= 2000
        hits, d_min, low = wc.coal_check(world)
        assert hits == 0 and d_min > 0 and low > 0


DATA = Path(__file__).parent / "data"


def _restart_loop(term, q, dq, restarts=16, touching=1e-12):
    """The straight-line check restarting every pair from the earliest CCD stop, with a new
    swept query each time (World::path_crosses before line_crosses), under the rule that
    line_crosses states: a restart from a gap <= `touching` is contact."""
    t = 0.0
    for k in range(restarts):
        if k > 0 and term.min_distance(q + t * dq, touching) <= touching:
            return True
        alpha = term.max_step(q + t * dq, (1.0 - t) * dq)
        if alpha >= 1.0:
            return False
        t += (1.0 - t) * alpha
    return True


def test_line_crosses_restarts_only_the_pairs_it_did_not_clear():
    """The straight-line check of a step (IpcContactTerm::line_crosses) queries once and
    restarts only the pairs whose CCD stopped short, each from its own stop: the same answers
    as restarting everything from the earliest stop with a query each time, on chords of a
    landing heap spanning 1-8 steps, of which some cross and some do not."""
    world = heap()
    states = [world.q.copy()]
    for _ in range(36):
        world.step()
        states.append(world.q.copy())
    term = world.contact
    answers = []
    for span in (1, 4, 8):
        for k in range(12, len(states) - span, 2):
            q, dq = states[k], states[k + span] - states[k]
            new = term.line_crosses(q, dq, 16, 1e-12)
            assert new == _restart_loop(term, q, dq), f"states {k} -> {k + span}"
            answers.append(new)
    assert 0 < sum(answers) < len(answers)


def test_a_line_that_closes_to_round_off_crosses_whatever_the_ccd_answers_after():
    """The straight line between two states of a landing 20-box heap (states 28 and 36 of an
    earlier build's trajectory, stored) takes an edge of box 12 through a face of box 4 at
    0.38709 of the line. Restarted from its stops, that pair's CCD closes its gap tenfold per
    restart (6e-7 m, 6e-8 m, ..., 2.6e-17 m after 11 restarts); from a gap at round-off its
    distances are noise, it finds no impact and advances 0.70 of the rest of the line, past
    the crossing, and from there the line is clear. So a restart from a gap <= the touching
    gap is contact, whatever its CCD then answers: the line crosses, however many restarts are
    allowed, both when line_crosses restarts only the pairs its query did not clear and when
    it restarts everything (its query had to shorten the moves). Before this rule,
    line_crosses called the line clear, and so did the restart loop given 32 restarts (with 16
    it ran out of them: crossing, by chance)."""
    q0, q1 = np.load(DATA / "heap20_chord_28_36.npy")
    dq = q1 - q0
    term = heap().contact
    with pytest.raises(ValueError, match="bodies 12 and 4 intersect"):
        term.check_initial(q0 + 0.45 * dq)
    term.check_initial(q1)  # both ends are valid states: only the line between them crosses
    for restarts in (16, 32, 64):
        assert term.line_crosses(q0, dq, restarts, 1e-12)
        assert _restart_loop(term, q0, dq, restarts)
    # A query cap that the swept query of the whole line exceeds: its moves are shortened, and
    # line_crosses restarts everything (with the old rule: clear, given 32 or 64 restarts).
    term.max_candidates = 1000
    for restarts in (16, 32, 64):
        assert term.line_crosses(q0, dq, restarts, 1e-12)


@pytest.mark.parametrize(
    ("restarts", "touching", "message"),
    [
        (0, 0.0, "restarts must be >= 1, got 0"),
        (-3, 0.0, "restarts must be >= 1, got -3"),
        (16, float("nan"), "touching gap must be finite and >= 0"),
        (16, float("inf"), "touching gap must be finite and >= 0"),
        (16, -1e-12, "touching gap must be finite and >= 0"),
    ],
)
def test_line_crosses_rejects_meaningless_restarts_and_gaps(restarts, touching, message):
    """With no restart every crossing line would read as clear (or every line as crossing),
    and a NaN touching gap compares false with every gap: both are refused by name."""
    term = heap().contact
    q0, q1 = np.load(DATA / "heap20_chord_28_36.npy")
    with pytest.raises(ValueError, match=message):
        term.line_crosses(q0, q1 - q0, restarts, touching)
