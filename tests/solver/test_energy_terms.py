"""Extra energy terms through the EnergyTerm interface (here written in Python): coupled
Newton systems (sparse direct and PCG), the CCD step bound (max_step) in the line search,
and the interface's contract checks."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from abdsim._native import _core

H = 0.01


def jacobian(x_bar: np.ndarray) -> np.ndarray:
    J = np.zeros((3, 12))
    J[:, :3] = np.eye(3)
    for k in range(3):
        J[k, 3 + 3 * k : 6 + 3 * k] = x_bar
    return J


class Spring(_core.PythonEnergyTerm):
    """Zero-length spring k/2 |x_a - x_b|² between material points of bodies a and b."""

    def __init__(self, a, b, x_bar_a, x_bar_b, k, bodies=None):
        if bodies is None:
            super().__init__()
        else:
            super().__init__(bodies=bodies)
        self.a, self.b, self.k = a, b, k
        self.Ja, self.Jb = jacobian(np.asarray(x_bar_a)), jacobian(np.asarray(x_bar_b))

    def name(self):
        return "spring"

    def _d(self, q):
        return (
            self.Ja @ q[12 * self.a : 12 * self.a + 12]
            - self.Jb @ q[12 * self.b : 12 * self.b + 12]
        )

    def value(self, q):
        d = self._d(q)
        return 0.5 * self.k * d @ d

    def gradient(self, q):
        g = np.zeros_like(q)
        d = self._d(q)
        g[12 * self.a : 12 * self.a + 12] += self.k * self.Ja.T @ d
        g[12 * self.b : 12 * self.b + 12] -= self.k * self.Jb.T @ d
        return g

    def hessian(self, q):
        Ja, Jb, k = self.Ja, self.Jb, self.k
        return [
            (self.a, self.a, k * Ja.T @ Ja),
            (self.b, self.b, k * Jb.T @ Jb),
            (self.a, self.b, -k * Ja.T @ Jb),
            (self.b, self.a, -k * Jb.T @ Ja),
        ]


class Floor(_core.PythonEnergyTerm):
    """IPC-style barrier between the vertices of one body and the plane z = 0, with its
    continuous collision detection as max_step."""

    def __init__(self, body, x_bar, d_hat=0.01, stiffness=1e4):
        super().__init__()
        self.body, self.x_bar, self.d_hat, self.kappa = body, x_bar, d_hat, stiffness

    def name(self):
        return "floor"

    def _z(self, q):  # vertex heights and their gradients dz/dq (rows)
        qb = q[12 * self.body : 12 * self.body + 12]
        z = self.x_bar @ qb[9:12] + qb[2]
        dz = np.zeros((len(z), 12))
        dz[:, 2] = 1.0
        dz[:, 9:12] = self.x_bar
        return z, dz

    def value(self, q):
        z, _ = self._z(q)
        if (z <= 0).any():
            return np.inf
        a = z[z < self.d_hat]
        return float(np.sum(-self.kappa * (a - self.d_hat) ** 2 * np.log(a / self.d_hat)))

    def gradient(self, q):
        z, dz = self._z(q)
        active = z < self.d_hat
        zz, d = z[active], z[active] - self.d_hat
        db = -self.kappa * (2 * d * np.log(zz / self.d_hat) + d * d / zz)
        g = np.zeros_like(q)
        g[12 * self.body : 12 * self.body + 12] = db @ dz[active]
        return g

    def hessian(self, q):
        z, dz = self._z(q)
        active = z < self.d_hat
        zz, d = z[active], z[active] - self.d_hat
        ddb = -self.kappa * (2 * np.log(zz / self.d_hat) + 4 * d / zz - d * d / (zz * zz))
        return [(self.body, self.body, (dz[active].T * ddb) @ dz[active])]

    def max_step(self, q, dq):
        z, dz = self._z(q)
        rate = dz @ dq[12 * self.body : 12 * self.body + 12]
        falling = rate < 0
        return float(min(1.0, np.min(z[falling] / -rate[falling], initial=np.inf)))


def two_boxes(tools, **settings):
    sc = tools.make_box(2)
    T = np.tile(np.eye(4), (2, 1, 1))
    T[1, 0, 3] = 1.0
    sc.transforms = T
    world = tools.world_of(sc, dt=H, gravity=(0, 0, 0), **settings)
    world.add_term(Spring(0, 1, np.zeros(3), np.zeros(3), k=2e3))
    return sc, world


def test_spring_matches_the_bdf1_recurrence(tools):
    """Spring between the centres: the relative coordinate r = x0 - x1 of two equal masses
    follows v' = v - h (2k/m) r', r' = r + h v' exactly; A stays the identity."""
    sc, world = two_boxes(tools)
    m, k = float(sc.meta["abd_mass"]), 2e3
    r, v = -1.0, 0.0
    analyses = 0
    for _ in range(30):
        analyses += world.step().profile["symbolic_analyses"]
        v = (v - H * 2 * k / m * r) / (1 + H * H * 2 * k / m)
        r = r + H * v
        x = world.transforms()[:, 0, 3]
        assert x[0] - x[1] == pytest.approx(r, abs=1e-9)
        assert x[0] + x[1] == pytest.approx(1.0, abs=1e-12)  # centre of mass at rest
    np.testing.assert_allclose(
        world.transforms()[:, :3, :3], np.tile(np.eye(3), (2, 1, 1)), atol=1e-12
    )
    d = world.diagnostics
    assert d.linear_solver == "direct"
    # The coupled pair never changes: one sparse analysis, reused by every later iteration.
    assert analyses == 1
    assert set(d.energies) == {"kinetic", "shape", "spring", "total"}
    assert d.energies["spring"] == pytest.approx(0.5 * k * r * r, rel=1e-6)


def test_direct_and_pcg_agree(tools, rng):
    results = {}
    V = np.stack(
        [tools.rigid_velocity(np.eye(3), rng.normal(size=3), np.zeros(3)) for _ in range(2)]
    )
    # PCG stops at a relative residual; over several Newton iterations per step (the tumbling
    # boxes need them) its error at the default 1e-8 accumulates to ~1e-8 in q. A tight
    # residual makes this a test of the two solvers solving the same system.
    for solver in ("direct", "pcg", "auto_pcg"):
        settings = {"linear_solver": solver} if solver != "auto_pcg" else {"direct_max_dofs": 0}
        settings["pcg_tolerance"] = 1e-13
        sc, world = two_boxes(tools, **settings)
        world.add_term(Spring(0, 1, [0.2, 0.1, 0.05], [-0.2, 0.1, -0.05], k=5e3))
        world.set_state(velocities=V)
        world.step(20)
        results[solver] = world.q
        assert world.diagnostics.linear_solver == ("pcg" if solver != "direct" else "direct")
        if solver != "direct":
            assert world.diagnostics.pcg_iterations > 0
    np.testing.assert_allclose(results["pcg"], results["direct"], atol=1e-8)
    np.testing.assert_allclose(results["auto_pcg"], results["pcg"], atol=0)


def test_internal_spring_conserves_linear_momentum(tools):
    sc, world = two_boxes(tools)
    world.add_term(Spring(0, 1, [0.2, 0.1, 0.05], [-0.2, -0.1, 0.05], k=5e3))
    V = np.zeros((2, 4, 4))
    V[0] = tools.rigid_velocity(np.eye(3), [0.0, 1.0, 2.0], [0.1, 0.0, 0.0])
    world.set_state(velocities=V)
    m, mx = float(sc.meta["abd_mass"]), np.asarray(sc.meta["abd_mass_x_bar"])

    def momentum():
        V = world.velocities()
        return (m * V[:, :3, 3] + V[:, :3, :3] @ mx).sum(axis=0)

    P0 = momentum()
    world.step(30)
    np.testing.assert_allclose(momentum(), P0, atol=1e-9)


def box_above_floor(tools, height: float):
    """A 0.2 x 0.2 x 0.1 box centred at `height` above a Floor barrier."""
    sc = tools.make_box(extents=(0.2, 0.2, 0.1))
    T = np.eye(4)
    T[2, 3] = height
    sc.transforms = T[None]
    world = tools.world_of(sc, dt=H)
    world.add_term(Floor(0, np.asarray(sc.positions)))
    return world, T


def test_barrier_floor_never_crossed(tools):
    """A box thrown down at a barrier floor (2 m/s: its prediction lies below the floor, so
    the CCD bound must act whatever the Newton start): the bound keeps every vertex above the
    plane at every step, and the box comes to rest within the barrier's range."""
    world, _ = box_above_floor(tools, 0.1)  # lowest vertices 5 cm above the floor
    V = np.zeros((1, 4, 4))
    V[0, 2, 3] = -2.0
    world.set_state(velocities=V)
    handle = world.scene.handles[0]
    limited = 0
    for _ in range(80):
        d = world.step()
        assert world.vertices(handle)[..., 2].min() > 0
        limited += d.min_term_max_step < 1
    assert limited > 0  # the step bound was active at least once
    z = world.vertices(handle)[0, :, 2]
    assert z.min() < 0.01  # resting in the barrier's range
    assert np.abs(world.velocities()).max() < 1e-2
    assert world.diagnostics.energies["floor"] > 0


class Asymmetric(Spring):
    def hessian(self, q):
        return super().hessian(q)[:3]  # forgets the (b, a) block


def test_non_symmetric_term_is_reported(tools):
    sc = tools.make_box(2)
    world = tools.world_of(sc, gravity=(0, 0, 0))
    world.add_term(Asymmetric(0, 1, np.zeros(3), [1.0, 0, 0], k=1e3))
    with pytest.raises(abdsim.SolverError, match="not symmetric"):
        world.step()


def test_shape_energy_term_matches_the_energy_functions(tools, rng):
    """ShapeEnergyTerm (the solver's per-body evaluation) against the foundation's
    shape_energy, and its PSD projection."""
    sc = tools.make_box(2)
    sc2 = tools.make_box(1, constitution="ARAP", kappa=1e9)
    world = tools.world_of(sc, sc2)
    term = _core.ShapeEnergyTerm(world.core.scene, True)
    q = np.concatenate(
        [
            np.r_[rng.normal(size=3), (np.eye(3) + 0.2 * rng.normal(size=(3, 3))).ravel()]
            for _ in range(3)
        ]
    )
    volume = [float(sc.meta["volume"])] * 2 + [float(sc2.meta["volume"])]
    uid, kappa = [1, 1, 2], [1e8, 1e8, 1e9]
    g = term.gradient(q)
    blocks = term.hessian(q)
    total = 0.0
    for b in range(3):
        e, g_ref, H_ref = _core.shape_energy(
            uid[b], q[12 * b : 12 * b + 12], kappa[b], volume[b], False
        )
        total += e
        np.testing.assert_allclose(g[12 * b : 12 * b + 12], g_ref, rtol=1e-12, atol=1e-6)
        row, col, Hb = blocks[b]
        assert row == col == b
        assert np.linalg.eigvalsh(Hb).min() > -1e-9 * np.abs(Hb).max()
        if uid[b] == 2:  # analytic projection: identical to the foundation's
            _, _, H_psd = _core.shape_energy(2, q[12 * b : 12 * b + 12], kappa[b], volume[b], True)
            np.testing.assert_allclose(Hb, H_psd, rtol=1e-12, atol=1e-6)
    assert term.value(q) == pytest.approx(total, rel=1e-12)
    # Stretched (AAᵀ - I PSD): the OrthoPotential Hessian needs no projection at all.
    q_stretched = np.r_[np.zeros(3), (1.05 * np.eye(3)).ravel()]
    q3 = np.concatenate([q_stretched] * 3)
    _, _, H_exact = _core.shape_energy(1, q_stretched, 1e8, volume[0], False)
    np.testing.assert_allclose(term.hessian(q3)[0][2], H_exact, rtol=1e-12, atol=1e-6)


def test_kinematic_motion_into_a_bound_is_driven_not_forced(tools):
    """A scripted move that an energy term's max_step forbids is not forced through: for that
    step the body is driven towards its target by a stiff spring, stops short of the floor,
    and the distance left is reported."""
    world, T = box_above_floor(tools, 0.06)  # lowest vertices 1 cm above the floor
    handle = world.scene.handles[0]
    down = T.copy()
    down[2, 3] = 0.055
    world.set_kinematic_target(0, down)  # 5 mm down: allowed, exact
    d = world.step()
    assert world.transforms()[0, 2, 3] == 0.055
    assert d.driven_bodies == 0 and d.kinematic_lag == 0
    down[2, 3] = 0.03  # 2.5 cm below the floor
    world.set_kinematic_target(0, down)
    d = world.step()
    z = world.vertices(handle)[0, :, 2]
    assert 0 < z.min() < 1e-3  # pressed onto the floor, not through it
    assert d.driven_bodies == 1 and d.kinematic_lag_body == 0
    assert d.kinematic_lag == pytest.approx(world.transforms()[0, 2, 3] - 0.03, rel=1e-3)
    assert "kinematic_drive" in d.energies
    assert world.is_kinematic(0)


def test_external_kinetic_body_is_driven_by_its_energy_alone(tools):
    """external_kinetic = 1: no inertia (and so no gravity through q̃); three zero-length
    springs to a fixed twin pull it onto the twin within one step."""
    sc = tools.make_box(2)
    T = np.tile(np.eye(4), (2, 1, 1))
    T[0, :3, 3] = [0.1, -0.05, 0.02]
    sc.transforms = T
    sc.instances["external_kinetic"] = np.array([1, 0])
    sc.instances["is_fixed"] = np.array([0, 1])
    world = tools.world_of(sc, dt=H, newton_tol_translation=1e-6, newton_tol_affine=1e-6)
    for x_bar in ([0.2, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.05]):
        world.add_term(Spring(0, 1, x_bar, x_bar, k=1e4))
    world.step()
    np.testing.assert_allclose(world.transforms()[0], np.eye(4), atol=1e-8)
    assert world.diagnostics.linear_solver == "block_diagonal"  # couplings to a fixed body drop
    np.testing.assert_allclose(world.velocities()[0, :3, 3], -T[0, :3, 3] / H, atol=1e-6)


def springs_among_free_boxes(tools, bodies):
    """12 boxes 1 m apart falling freely (no contact), a spring between boxes 0 and 1
    constructed with `bodies` (None: a term that may involve any body)."""
    sc = tools.make_box(12)
    T = np.tile(np.eye(4), (12, 1, 1))
    T[:, 0, 3] = np.arange(12.0)
    sc.transforms = T
    world = tools.world_of(sc, dt=H)
    world.add_term(Spring(0, 1, np.zeros(3), np.zeros(3), k=2e3, bodies=bodies))
    return world


def test_named_python_term_couples_only_its_bodies(tools):
    """A Python term that names its bodies couples those two; the ten others keep their
    own free-fall solve and fly the exact parabola (z_n = −½ g (n h)², BDF1 with
    solver/world_ballistic.cpp), and the two named bodies move as under the same term
    coupling everything. That term may push any body, so there every body keeps implicit
    Euler's recurrence z_n = −g h² n(n+1)/2."""
    steps, g = 10, 9.81
    everything = springs_among_free_boxes(tools, None)
    named = springs_among_free_boxes(tools, [0, 1])
    for _ in range(steps):
        d_all, d_named = everything.step(), named.step()
        assert d_all.coupled_bodies == 12
        assert d_named.coupled_bodies == 2
        assert d_named.islands == 1
    free = named.transforms()[2:]
    np.testing.assert_allclose(free[:, 2, 3], -0.5 * g * (steps * H) ** 2, rtol=1e-12)
    np.testing.assert_allclose(free[:, :3, :3], np.tile(np.eye(3), (10, 1, 1)), atol=1e-12)
    z_euler = -g * H * H * steps * (steps + 1) / 2
    np.testing.assert_allclose(everything.transforms()[2:, 2, 3], z_euler, rtol=1e-12)
    np.testing.assert_allclose(named.q[:2], everything.q[:2], atol=1e-9)
    r = named.transforms()[:2, 0, 3]
    assert r[1] - r[0] < 1.0  # the spring pulled them together


class Leaky(Spring):
    """A spring naming bodies 0 and 1 whose gradient or Hessian also touches body 2."""

    def __init__(self, where):
        super().__init__(0, 1, np.zeros(3), np.zeros(3), k=2e3, bodies=[0, 1])
        self.where = where

    def gradient(self, q):
        g = super().gradient(q)
        if self.where == "gradient":
            g[24] = 1.0
        return g

    def hessian(self, q):
        blocks = super().hessian(q)
        if self.where == "hessian":
            blocks += [(0, 2, np.eye(12)), (2, 0, np.eye(12))]
        return blocks


@pytest.mark.parametrize(
    ("where", "message"),
    [("gradient", "non-zero on body 2"), ("hessian", r"block \(0, 2\), outside")],
)
def test_named_python_term_stays_on_its_bodies(tools, where, message):
    sc = tools.make_box(3)
    T = np.tile(np.eye(4), (3, 1, 1))
    T[:, 0, 3] = np.arange(3.0)
    sc.transforms = T
    world = tools.world_of(sc, dt=H)
    world.add_term(Leaky(where))
    with pytest.raises(ValueError, match=message):
        world.step()


@pytest.mark.parametrize(
    ("bodies", "message"),
    [([], "bodies is empty"), ([0, 0], "body 0 is named twice"), ([-1], "body -1 is negative")],
)
def test_named_python_term_bad_bodies(bodies, message):
    assert Spring(0, 1, np.zeros(3), np.zeros(3), k=1.0, bodies=[1, 0]).bodies == [1, 0]
    with pytest.raises(ValueError, match=message):
        Spring(0, 1, np.zeros(3), np.zeros(3), k=1.0, bodies=bodies)


def test_named_python_term_out_of_range(tools):
    _, world = two_boxes(tools)
    world.add_term(Spring(0, 5, np.zeros(3), np.zeros(3), k=1.0, bodies=[0, 5]))
    with pytest.raises(ValueError, match="body 5 is out of range"):
        world.step()


class NonFinite(Spring):
    """A spring whose gradient has one entry replaced by `bad` (inf, -inf or NaN)."""

    def __init__(self, *args, bad, entry, **kwargs):
        super().__init__(*args, **kwargs)
        self.bad, self.entry = bad, entry

    def gradient(self, q):
        g = super().gradient(q)
        g[self.entry] = self.bad
        return g


@pytest.mark.parametrize("bad", [np.inf, -np.inf, np.nan])
@pytest.mark.parametrize("entry", [0, 13, 23])
def test_a_non_finite_gradient_is_reported_and_the_state_kept(tools, bad, entry):
    """One non-finite entry anywhere in ∇Π (first, middle or last of the two bodies' 24)
    stops the step with a SolverError naming the gradient, and the state stays as it was
    (the solver's vectorised finiteness check: x − x summed is NaN for any ±inf or NaN)."""
    sc = tools.make_box(2)
    world = tools.world_of(sc, gravity=(0, 0, 0))
    world.add_term(NonFinite(0, 1, np.zeros(3), [1.0, 0, 0], k=1e3, bad=bad, entry=entry))
    q = world.q.copy()
    with pytest.raises(abdsim.SolverError, match="gradient of Π is not finite"):
        world.step()
    np.testing.assert_array_equal(world.q, q)
