"""IPC barrier with thickness offset, and IPC's adaptive stiffness, vs closed forms and ipctk.

ipctk's `barrier(d, dhat)` is written for a generic distance measure; IPC applies it to squared
distances, i.e. ours is b(d²; d̂, 0) = ipctk.barrier(d², d̂²). With a thickness ξ our barrier is
ipctk's shifted by ξ²: b(d²; d̂, ξ) = ipctk.barrier(d² − ξ², d̂² + 2 d̂ ξ).
"""

import math

import ipctk
import numpy as np
import pytest

D_HAT = 1e-3


@pytest.mark.parametrize("xi", [0.0, 2e-3, 0.05])
def test_barrier_vs_ipctk(contact, xi):
    X = (D_HAT + xi) ** 2
    Y = xi**2
    for d2 in np.linspace(Y, X, 41)[1:-1]:
        ref = ipctk.barrier(d2 - Y, X - Y)
        assert contact.barrier(d2, D_HAT, xi) == pytest.approx(ref, rel=1e-9)
        assert contact.barrier_first_derivative(d2, D_HAT, xi) == pytest.approx(
            ipctk.barrier_first_derivative(d2 - Y, X - Y), rel=1e-9
        )
        assert contact.barrier_second_derivative(d2, D_HAT, xi) == pytest.approx(
            ipctk.barrier_second_derivative(d2 - Y, X - Y), rel=1e-9
        )


@pytest.mark.parametrize("xi", [0.0, 0.01])
def test_barrier_closed_form_and_derivatives(contact, xi):
    X = (D_HAT + xi) ** 2
    Y = xi**2
    for d in np.linspace(xi, xi + D_HAT, 13)[1:-1]:
        d2 = d * d
        expected = -((d2 - X) ** 2) * math.log((d2 - Y) / (D_HAT**2 + 2 * D_HAT * xi))
        assert contact.barrier(d2, D_HAT, xi) == pytest.approx(expected, rel=1e-12)
        h = 1e-6 * (d2 - Y)
        fd1 = (contact.barrier(d2 + h, D_HAT, xi) - contact.barrier(d2 - h, D_HAT, xi)) / (2 * h)
        fd2 = (
            contact.barrier_first_derivative(d2 + h, D_HAT, xi)
            - contact.barrier_first_derivative(d2 - h, D_HAT, xi)
        ) / (2 * h)
        assert contact.barrier_first_derivative(d2, D_HAT, xi) == pytest.approx(fd1, rel=1e-6)
        assert contact.barrier_second_derivative(d2, D_HAT, xi) == pytest.approx(fd2, rel=1e-6)
        # force magnitude −∂(κb)/∂d by the chain rule
        lam = contact.barrier_force_magnitude(d2, D_HAT, xi, 2.0)
        assert lam == pytest.approx(-2.0 * 2 * d * contact.barrier_first_derivative(d2, D_HAT, xi))
        assert lam > 0


def test_barrier_support(contact):
    xi = 0.01
    X = (D_HAT + xi) ** 2
    # zero with zero first and second derivative at and beyond d̂ (C² activation)
    for d2 in [X, 1.5 * X]:
        assert contact.barrier(d2, D_HAT, xi) == 0.0
        assert contact.barrier_first_derivative(d2, D_HAT, xi) == 0.0
        assert contact.barrier_second_derivative(d2, D_HAT, xi) == 0.0
    assert abs(contact.barrier_second_derivative(X * (1 - 1e-9), D_HAT, xi)) < 1e-6
    # infinite at and inside the thickness
    assert contact.barrier(xi**2, D_HAT, xi) == math.inf
    assert contact.barrier(0.5 * xi**2, D_HAT, xi) == math.inf
    assert contact.barrier_first_derivative(xi**2, D_HAT, xi) == -math.inf
    # monotone decreasing, convex inside the support
    d2 = np.linspace(xi**2, X, 50)[1:-1]
    b = np.array([contact.barrier(v, D_HAT, xi) for v in d2])
    assert np.all(np.diff(b) < 0)
    assert all(contact.barrier_second_derivative(v, D_HAT, xi) > 0 for v in d2)


def test_adaptive_stiffness_matches_ipctk(contact, rng):
    # abdsim scales every term by h² in Π, IPC does not scale the barrier: κ_abdsim h² = κ_IPC.
    dt, diag, mass = 0.01, 2.0, 3.5
    ge, gb = rng.normal(size=24), rng.normal(size=24)
    kappa, kmin, kmax = contact.initial_barrier_stiffness(diag, D_HAT, mass, dt, ge, gb)
    ref_kappa, ref_kmax = ipctk.initial_barrier_stiffness(
        diag, ipctk.ClampedLogBarrier(), D_HAT, mass, ge, gb
    )
    assert kmax * dt**2 == pytest.approx(ref_kmax, rel=1e-9)
    assert kmin * dt**2 == pytest.approx(ref_kmax / 100, rel=1e-9)
    assert kappa * dt**2 == pytest.approx(ref_kappa, rel=1e-9)
    # the gradient balance inside the bounds
    gb_small = gb * 1e-9
    ge_bal = -gb_small * (kmin * 7 * dt**2)
    kappa, _, _ = contact.initial_barrier_stiffness(diag, D_HAT, mass, dt, ge_bal, gb_small)
    assert kappa == pytest.approx(7 * kmin, rel=1e-9)
    # no contact: the lower bound
    kappa, kmin2, _ = contact.initial_barrier_stiffness(diag, D_HAT, mass, dt, ge, 0 * gb)
    assert kappa == kmin2 == pytest.approx(kmin)


def test_update_stiffness(contact):
    diag = 1.0
    eps = 1e-9 * diag
    assert contact.update_barrier_stiffness(0.5 * eps, 0.4 * eps, 100.0, 3.0, diag) == 6.0
    assert contact.update_barrier_stiffness(0.5 * eps, 0.4 * eps, 5.0, 3.0, diag) == 5.0
    assert contact.update_barrier_stiffness(0.4 * eps, 0.5 * eps, 100.0, 3.0, diag) == 3.0
    assert contact.update_barrier_stiffness(2 * eps, 0.5 * eps, 100.0, 3.0, diag) == 3.0
    # ipctk states the same rule on squared distances
    for prev, cur in [(0.5, 0.4), (0.4, 0.5), (2.0, 0.5), (0.9, 0.8)]:
        ours = contact.update_barrier_stiffness(prev * eps, cur * eps, 100.0, 3.0, diag)
        ref = ipctk.update_barrier_stiffness((prev * eps) ** 2, (cur * eps) ** 2, 100.0, 3.0, diag)
        assert ours == ref
