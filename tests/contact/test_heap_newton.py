"""A heap of boxes landing and coming to rest (issue 12's scene, 20 boxes): Newton starts each
island at its warm guess (the last step's contact forces carried over, World::warm_guess), so
the resting heap takes one or two Newton iterations a step (steps 150-199: median 1, at most
2; steps 100-149 had median 1, at most 3, before majorised friction steps changed the
trajectory, and median 12, 8-40, when every island started where it was), without
intersections (coal)."""

from __future__ import annotations

import numpy as np

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
        world.step()
    d = world.step()
    assert d.substeps == 8
    assert "still crosses after pieces of dt / 8 everywhere" in d.substep_reason
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
