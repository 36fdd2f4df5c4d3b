"""Same input, same bits (any thread count); what a step reports about itself."""

from __future__ import annotations

import numpy as np
import pytest


def spinning_boxes(tools, n=300, seed=3):
    rng = np.random.default_rng(seed)
    sc = tools.make_box(n)
    T = np.tile(np.eye(4), (n, 1, 1))
    T[:, :3, :3] = tools.random_rotations(rng, n)
    T[:, :3, 3] = rng.uniform(-5, 5, size=(n, 3))
    sc.transforms = T
    sc.instances["velocity"] = np.stack(
        [
            tools.rigid_velocity(A, rng.normal(scale=5.0, size=3), rng.normal(size=3))
            for A in T[:, :3, :3]
        ]
    )
    return sc


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_bit_identical_trajectories(tools, integrator):
    runs = []
    for threads in (1, 2, 1):
        world = tools.world_of(spinning_boxes(tools), integrator=integrator, num_threads=threads)
        trajectory = []
        for _ in range(5):
            world.step(4)
            trajectory.append(world.q)
        runs.append(np.stack(trajectory))
    assert np.array_equal(runs[0], runs[2])  # same input twice
    assert np.array_equal(runs[0], runs[1])  # 1 or 2 threads


def test_diagnostics_and_history(tools):
    world = tools.world_of(spinning_boxes(tools, n=50), history_limit=3)
    assert world.diagnostics is None
    d = world.step(5, progress=True)
    assert d.step == 4 and d.time == pytest.approx(0.05)
    assert d.converged and 1 <= d.newton_iterations <= 5
    assert d.total_body_iterations >= 50
    assert len(d.line_search_alphas) == d.newton_iterations
    assert all(0 < a <= 1 for a in d.line_search_alphas)
    assert d.step_affine <= world.scene.settings.newton_tol_affine
    assert d.step_translation <= world.scene.settings.newton_tol_translation
    assert d.linear_solver == "block_diagonal" and d.min_term_max_step == 1.0
    assert set(d.energies) == {"kinetic", "shape", "total"}
    h2 = world.scene.dt**2
    assert d.energies["total"] == pytest.approx(d.energies["kinetic"] + h2 * d.energies["shape"])
    assert d.energies["shape"] > 0  # spinning bodies stretch a little
    assert d.wall_time > 0
    history = world.history
    assert [s.step for s in history] == [2, 3, 4]
    assert history[-1] == d


def test_sync_and_vertices(tools):
    sc = tools.make_box(2)
    world = tools.world_of(sc, dt=0.01)
    world.step(10)
    handle = world.scene.handles[0]
    x = world.vertices(handle)
    T = world.transforms()
    np.testing.assert_allclose(
        x, np.einsum("kij,vj->kvi", T[:, :3, :3], sc.positions) + T[:, None, :3, 3]
    )
    world.sync()
    np.testing.assert_array_equal(sc.transforms, T)
    np.testing.assert_array_equal(sc.instances["velocity"], world.velocities())
    assert sc.meta["dof_offset"] == 0 and sc.meta["dof_count"] == 24


def test_last_diagnostics_survive_history_changes(tools):
    # Every step's diagnostics have one owner, the World's deque of kept steps (moved there,
    # not copied), which always keeps the last step: clearing or shrinking the history to
    # nothing must leave it readable, and the history shows only steps since it was cleared.
    # Python reads copies (a reference into a dropped step would dangle).
    world = tools.world_of(spinning_boxes(tools, n=3), history_limit=2)
    assert world._core.history == [] and world._core.diagnostics.step == 0
    assert not world._core.diagnostics.converged  # nothing stepped yet: the defaults
    world.step(3)
    core = world._core
    last = core.diagnostics
    assert [s.step for s in core.history] == [1, 2] and last.step == 2
    energies = dict(last.energies)
    core.clear_history()
    assert core.history == [] and core.diagnostics.step == 2
    assert dict(core.diagnostics.energies) == energies
    world.step()
    assert [s.step for s in core.history] == [3] and core.diagnostics.step == 3
    core.set_history_limit(0)
    assert core.history == [] and core.diagnostics.step == 3
    world.step()
    assert core.history == [] and core.diagnostics.step == 4
    core.set_history_limit(5)
    world.step(2)
    assert [s.step for s in core.history] == [5, 6] and core.diagnostics.step == 6
    core.set_history_limit(1)
    assert [s.step for s in core.history] == [6] and core.diagnostics.step == 6
    assert core.history[0].wall_time == core.diagnostics.wall_time  # the same step


def test_trimmed_history_reports_each_step_s_own_lists(tools):
    # A step dropped from a full history lends its lists' storage (energies, line-search
    # alphas) to the next step's diagnostics: the steps kept must still report their own
    # values, those of a World that never dropped a step (the same steps, bit for bit).
    short = tools.world_of(spinning_boxes(tools, n=4), history_limit=2)
    long = tools.world_of(spinning_boxes(tools, n=4), history_limit=100)
    for _ in range(6):
        short.step()
        long.step()
        for a, b in zip(short.history, long.history[-2:], strict=True):
            assert a.step == b.step
            assert a.energies == b.energies
            assert a.line_search_alphas == b.line_search_alphas
    assert [d.step for d in short.history] == [4, 5]
    assert short.history[-1].energies["total"] == pytest.approx(
        short.history[-1].energies["kinetic"]
        + short.scene.dt**2 * short.history[-1].energies["shape"]
    )


def test_energies_off_on_the_per_body_path(tools):
    # Bodies solved alone report their energies from their own Newton solves; off, nothing,
    # and the same motion to the bit.
    on = tools.world_of(spinning_boxes(tools, n=6))
    off = tools.world_of(spinning_boxes(tools, n=6), energies=False)
    on.step(5)
    off.step(5)
    np.testing.assert_array_equal(on.q, off.q)
    assert set(on.diagnostics.energies) == {"kinetic", "shape", "total"}
    assert off.diagnostics.energies == {} and off.diagnostics.newton_iterations > 0
