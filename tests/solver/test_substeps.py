"""Steps Newton cannot solve in its budget are retried as substeps before a SolverError, and
the error reports the criterion that failed."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from tests.solver.test_ballistic import Zero


def _falling_box(max_iterations: int, speed: float, dt: float) -> abdsim.World:
    scene = abdsim.Scene(dt=dt, newton_max_iterations=max_iterations, integrator="bdf2")
    scene.add_ground(0.0)
    sc = abdsim.geometry.box(0.2)
    abdsim.AffineBodyConstitution().apply_to(sc, 1e8)
    T = np.eye(4)
    T[2, 3] = 0.15
    sc.transforms = T
    V = np.zeros((4, 4))
    V[:3, 3] = (1.0, 0.0, -speed)
    sc.instances["velocity"] = V
    scene.add(sc)
    return abdsim.World(scene)


def test_a_step_newton_cannot_solve_is_split_and_lands_the_box():
    # 11 Newton iterations cannot resolve a 5 m/s landing in one 0.05 s step (this raised
    # SolverError before); in pieces they can. (Newton converges only on a step the line
    # search took whole, and friction is lagged again after convergence: the landing takes
    # more iterations than the 5 this test used when a short direction counted as done.)
    world = _falling_box(11, 5.0, 0.05)
    first = world.step()
    assert first.substeps > 1 and first.time == pytest.approx(0.05)
    assert first.substep_reason.startswith("Newton did not converge in 11 iterations")
    world.step(9)
    assert world.time == pytest.approx(0.5)
    # resting on the ground (box half-size 0.1, gap within d̂ = 1e-3), not through it
    corners = world.vertices(world.scene.handles[0])[0]
    assert 0.0 < corners[:, 2].min() < 2e-3
    # the next steps are whole again
    assert [d.substeps for d in world.history[-5:]] == [1] * 5
    assert [d.substep_reason for d in world.history[-5:]] == [""] * 5


def test_when_even_substeps_fail_the_state_is_kept_and_the_error_says_why():
    world = _falling_box(3, 20.0, 0.05)
    q0 = world.q
    with pytest.raises(abdsim.SolverError) as err:
        world.step()
    msg = str(err.value)
    assert "Newton did not converge in 3 iterations" in msg
    assert "splitting it into pieces down to dt / 1024 did not help" in msg
    np.testing.assert_array_equal(world.q, q0)
    assert world.step_count == 0 and world.time == 0.0


def test_the_error_reports_the_tolerances_actually_applied():
    # A box sliding on the ground with friction is held to tolerances tighter than the
    # settings' (0.01 m/s, 0.1 1/s): the message says so instead of quoting tolerances its
    # last step may already meet.
    scene = abdsim.Scene(dt=0.01, newton_max_iterations=1, friction=0.5)
    scene.add_ground(0.0)
    sc = abdsim.geometry.box(0.2)
    abdsim.AffineBodyConstitution().apply_to(sc, 1e8)
    T = np.eye(4)
    T[2, 3] = 0.1 + 5e-4
    sc.transforms = T
    V = np.zeros((4, 4))
    V[0, 3] = 1.0
    sc.instances["velocity"] = V
    scene.add(sc)
    world = abdsim.World(scene)
    with pytest.raises(abdsim.SolverError) as err:
        world.step()
    msg = str(err.value)
    assert "the tolerances applied to bodies near contact are tighter than the settings" in msg
    applied = float(msg.split("than the settings: ")[1].split(" m/s")[0])
    assert 0 < applied < 0.01


def test_after_a_split_step_bdf2_goes_on_without_a_bdf1_restart():
    """A split step leaves BDF2 a history one piece long; each body gets instead the history
    of its last piece's (constant) acceleration over a whole step (solver/bdf_history.h), so
    the next step is BDF2 (it was a BDF1 restart, ½ g h² = 12 mm low here). A second box,
    tossed upward and spinning far from the landing one, follows from the state after the
    split step the closed-form parabola to round-off (measured ≤ 1e-15 m), in height and
    vertical velocity."""
    scene = abdsim.Scene(dt=0.05, newton_max_iterations=11, integrator="bdf2")
    scene.add_ground(0.0)
    sc = abdsim.geometry.box(0.2)
    sc.instances.resize(2)
    T = np.array(sc.transforms)
    T[0, 2, 3] = 0.15
    T[1, :3, 3] = (5.0, 0.0, 3.0)
    sc.transforms = T
    abdsim.AffineBodyConstitution().apply_to(sc, 1e8)
    sc.instances["velocity"][0][:3, 3] = (1.0, 0.0, -5.0)  # lands in pieces (as above)
    sc.instances["velocity"][1][:3, 3] = (0.3, 0.0, 2.0)
    sc.instances["velocity"][1][:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 0]]  # spin about z
    scene.add(sc)
    world = abdsim.World(scene)
    assert world.step().substeps > 1
    z0, v0 = world.transforms()[1, 2, 3], world.velocities()[1, 2, 3]
    z, vz = [], []
    for _ in range(5):
        assert world.step().integrator_order == 2
        z.append(world.transforms()[1, 2, 3])
        vz.append(world.velocities()[1, 2, 3])
    t = 0.05 * np.arange(1, 6)
    np.testing.assert_allclose(z, z0 + v0 * t - 0.5 * 9.81 * t * t, rtol=0, atol=1e-13)
    np.testing.assert_allclose(vz, v0 - 9.81 * t, rtol=0, atol=1e-12)


class _AssemblyCounter(Zero):
    """A zero potential on one body that counts the Newton systems assembled (one Hessian
    each): an independent count of the Newton iterations a step really took."""

    def __init__(self) -> None:
        super().__init__(bodies=[0])
        self.assemblies = 0

    def name(self) -> str:
        return "assembly counter"

    def hessian(self, q):
        self.assemblies += 1
        return []


def test_a_split_step_counts_every_newton_iteration_it_took():
    """The iterations of a split step count all the work: the whole step's failed attempt,
    pieces that failed and were halved again, and kept pieces (failed pieces were left out,
    so a step that cost hundreds of iterations could report a handful)."""
    world = _falling_box(11, 5.0, 0.05)
    counter = _AssemblyCounter()
    world.add_term(counter)
    first = world.step()
    assert first.substeps > 1
    assert counter.assemblies > 11 + first.substeps  # the failed whole step, then pieces
    assert first.newton_iterations == counter.assemblies
