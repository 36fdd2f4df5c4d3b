"""End-to-end use of IpcContactTerm through the EnergyTerm contract, with a minimal projected
Newton time stepper written here in numpy (implicit Euler, ABD_NOTES §6), only to exercise
the contract: begin_step → update → gradient/Hessian → max_step → line search on value.
The real solver lives elsewhere; these are physical sanity checks of the contact layer."""

import numpy as np
import pytest

from abdsim._native import _core

H_STEP, G = 0.01, 9.81
KAPPA_SHAPE = 1e8


class MiniStepper:
    def __init__(self, scenes, mu, q0, v0, d_hat=1e-3, kappa=1e9):
        self.V, self.F = scenes.box((0.1, 0.1, 0.1))
        m, mx, S = _core.closed_surface_mass(self.V, self.F, 1000.0)
        self.M = _core.mass_matrix(m, mx, S)
        self.volume = m / 1000.0
        self.term = scenes.term(
            [{"V": self.V, "F": self.F}],
            [0],
            q0[None, :],
            mass=[m],
            d_hat=d_hat,
            kappa=kappa,
            ground=True,
            ground_height=0.0,
            mu=mu,
            eps_v=1e-3,
            dt=H_STEP,
        )
        self.term.check_initial(q0)
        self.q, self.v = q0.copy(), v0.copy()
        self.min_gap = np.inf

    def energy(self, q, q_tilde):
        d = q - q_tilde
        shape = _core.shape_energy(1, q, KAPPA_SHAPE, self.volume)[0]
        return 0.5 * d @ self.M @ d + H_STEP**2 * (shape + self.term.value(q))

    def step(self):
        g_q = np.zeros(12)
        g_q[2] = -G
        q_t = self.q
        q_tilde = q_t + H_STEP * self.v + H_STEP**2 * g_q
        self.term.begin_step(q_t, H_STEP)
        q = q_t.copy()
        for _ in range(60):
            self.term.update(q)
            _, gs, hs = _core.shape_energy(1, q, KAPPA_SHAPE, self.volume, True)
            grad = self.M @ (q - q_tilde) + H_STEP**2 * (gs + self.term.gradient(q))
            hess = self.M + H_STEP**2 * (hs + self.term.hessian(q))
            dq = -np.linalg.solve(hess, grad)
            if np.abs(dq).max() < 1e-9:
                break
            alpha = self.term.max_step(q, dq)
            e0 = self.energy(q, q_tilde)
            while self.energy(q + alpha * dq, q_tilde) > e0 and alpha > 1e-12:
                alpha *= 0.5
            q = q + alpha * dq
        self.term.check_initial(q)  # never an invalid configuration
        self.min_gap = min(self.min_gap, self.term.min_distance(q, 1.0))
        self.v = (q - q_t) / H_STEP
        self.q = q


def box_q(x, z):
    return np.array([x, 0, z, 1, 0, 0, 0, 1, 0, 0, 0, 1], float)


def test_dropped_box_comes_to_rest_above_the_ground(scenes):
    v0 = np.zeros(12)
    v0[2] = -1.0  # falling at 1 m/s from 1 cm
    sim = MiniStepper(scenes, mu=0.0, q0=box_q(0, 0.05 + 0.01), v0=v0)
    for _ in range(60):
        sim.step()
    gap = sim.term.min_distance(sim.q)
    assert 0 < sim.min_gap and 0 < gap < 1e-3  # resting inside the barrier's reach
    assert abs(sim.v[2]) < 1e-3
    # the four bottom vertices carry the weight: Σλ = m g, i.e. the barrier force balances it
    m = sim.M[0, 0]
    force = -sim.term.gradient(sim.q)[2]
    assert force == pytest.approx(m * G, rel=1e-3)


def test_sliding_box_stops_after_the_coulomb_distance(scenes):
    # rest first (so friction has a normal force), then launch horizontally at 1 m/s
    sim = MiniStepper(scenes, mu=0.5, q0=box_q(0, 0.05 + 5e-4), v0=np.zeros(12))
    for _ in range(20):
        sim.step()
    x0 = sim.q[0]
    sim.v[0] = 1.0
    for _ in range(40):
        sim.step()
    travelled = sim.q[0] - x0
    # v²/(2μg) = 0.102 m continuously; implicit Euler applies each step's deceleration μ g h
    # before moving, which takes v h / 2 off: Σ_k h (v − k μ g h) = v²/(2μg) − v h/2.
    expected = 1.0**2 / (2 * 0.5 * G) - 1.0 * H_STEP / 2
    assert travelled == pytest.approx(expected, rel=0.01)
    assert abs(sim.v[0]) < 2e-3  # stopped (creep below ε_v)
    assert sim.min_gap > 0
