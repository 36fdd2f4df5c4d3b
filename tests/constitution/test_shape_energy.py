"""Shape energies against central finite differences, invariance under rotations, PSD."""

import numpy as np
import pytest

import abdsim

KAPPA, VOLUME = 1e8, 1e-3
NAMES = ["OrthoPotential", "ARAP"]


def q_of(A, p=(0.1, -0.2, 0.3)):
    return np.concatenate([np.asarray(p, float), A.reshape(-1)])  # rows of A after p


def sample_As(rng, random_rotation):
    near = [random_rotation(rng) @ (np.eye(3) + 1e-2 * rng.normal(size=(3, 3))) for _ in range(3)]
    strong = [
        random_rotation(rng) @ np.diag(rng.uniform(0.4, 1.8, 3)) @ random_rotation(rng)
        + 0.3 * rng.normal(size=(3, 3))
        for _ in range(3)
    ]
    return near + strong


def fd_gradient(f, q, h):
    g = np.zeros(12)
    for i in range(12):
        e = np.zeros(12)
        e[i] = h
        g[i] = (f(q + e) - f(q - e)) / (2 * h)
    return g


@pytest.mark.parametrize("name", NAMES)
def test_gradient_matches_finite_differences(name, rng, random_rotation):
    c = abdsim.AffineBodyConstitution(name)
    for A in sample_As(rng, random_rotation):
        q = q_of(A)
        e = c.energy(q, KAPPA, VOLUME)
        g_fd = fd_gradient(lambda x: c.energy(x, KAPPA, VOLUME).value, q, 1e-6)
        scale = np.abs(e.gradient).max()
        assert np.abs(e.gradient - g_fd).max() <= 1e-6 * scale + 1e-9
        np.testing.assert_array_equal(e.gradient[:3], 0.0)


@pytest.mark.parametrize("name", NAMES)
def test_hessian_matches_finite_differences(name, rng, random_rotation):
    c = abdsim.AffineBodyConstitution(name)
    for A in sample_As(rng, random_rotation):
        q = q_of(A)
        H = c.energy(q, KAPPA, VOLUME).hessian
        h = 1e-6
        H_fd = np.zeros((12, 12))
        for i in range(12):
            d = np.zeros(12)
            d[i] = h
            H_fd[:, i] = (
                c.energy(q + d, KAPPA, VOLUME).gradient - c.energy(q - d, KAPPA, VOLUME).gradient
            ) / (2 * h)
        assert np.abs(H - H_fd).max() <= 1e-5 * np.abs(H).max()
        np.testing.assert_allclose(H, H.T, atol=1e-9 * np.abs(H).max())


@pytest.mark.parametrize("name", NAMES)
def test_zero_at_any_rotation(name, rng, random_rotation):
    c = abdsim.AffineBodyConstitution(name)
    for _ in range(10):
        e = c.energy(q_of(random_rotation(rng), p=rng.normal(size=3)), KAPPA, VOLUME)
        assert abs(e.value) < 1e-20 * KAPPA
        assert np.abs(e.gradient).max() < 1e-12 * KAPPA * VOLUME


@pytest.mark.parametrize("name", NAMES)
def test_projected_hessian_is_psd_and_exact_when_convex(name, rng, random_rotation):
    c = abdsim.AffineBodyConstitution(name)
    for A in sample_As(rng, random_rotation):
        q = q_of(A)
        Hp = c.energy(q, KAPPA, VOLUME, project_psd=True).hessian
        lam = np.linalg.eigvalsh(Hp)
        assert lam.min() >= -1e-9 * lam.max()
        H = c.energy(q, KAPPA, VOLUME).hessian
        lam_raw = np.linalg.eigvalsh(H)
        if lam_raw.min() >= 0:
            np.testing.assert_allclose(Hp, H, atol=1e-8 * lam.max())
        else:
            # projection only removes the negative part: Hp - H is PSD
            assert np.linalg.eigvalsh(Hp - H).min() >= -1e-8 * lam.max()


def test_values_against_definitions(rng, random_rotation):
    A = np.diag([1.2, 0.9, 1.0])
    ortho = abdsim.AffineBodyConstitution("OrthoPotential").energy(q_of(A), 2.0, 3.0)
    assert ortho.value == pytest.approx(6.0 * ((1.44 - 1) ** 2 + (0.81 - 1) ** 2), rel=1e-14)
    R = random_rotation(rng)
    arap = abdsim.AffineBodyConstitution("ARAP").energy(q_of(R @ A), 2.0, 3.0)
    assert arap.value == pytest.approx(6.0 * (0.2**2 + 0.1**2), rel=1e-12)


def test_energy_bad_input():
    c = abdsim.AffineBodyConstitution()
    with pytest.raises(ValueError, match="12 entries"):
        c.energy(np.zeros(9), 1.0, 1.0)
    with pytest.raises(ValueError, match="NaN"):
        c.energy(np.full(12, np.nan), 1.0, 1.0)
    with pytest.raises(ValueError, match="unknown constitution"):
        abdsim.AffineBodyConstitution("NeoHookean")


@pytest.mark.parametrize("name", NAMES)
def test_projection_clamps_and_leaves_rotations_alone(name, rng, random_rotation):
    """The projected Hessian is the eigenvalue clamp of the exact one (numpy's eigh as the
    reference), also at near-rotations (a compressed body, AAᵀ − I slightly negative), where
    a shift of every eigenvalue would give the rotational modes δA = W A a stiffness."""
    c = abdsim.AffineBodyConstitution(name)
    for scale in (0.999, 0.99, 0.9, 0.5):
        for _ in range(5):
            A = random_rotation(rng) @ np.diag(scale * (1.0 + 1e-3 * rng.normal(size=3)))
            q = q_of(A)
            H = c.energy(q, KAPPA, VOLUME).hessian
            lam, vec = np.linalg.eigh(H)
            clamped = (vec * np.maximum(lam, 0.0)) @ vec.T
            Hp = c.energy(q, KAPPA, VOLUME, project_psd=True).hessian
            np.testing.assert_allclose(Hp, clamped, atol=1e-9 * np.abs(lam).max())


def test_projection_of_near_rotations_stretched_and_compressed(rng, random_rotation):
    """Near rest a body is stretched along some axes and compressed along others (AAᵀ − I
    indefinite). The projection skips its eigen-solve when no mode can be negative (the
    "−" modes 4(μ_i + μ_j − 1 − σ_iσ_j) are bounded below by 2(μ_i + μ_j − 2)): there the
    projected Hessian must be the exact one to the bit, and elsewhere numpy's clamp."""
    c = abdsim.AffineBodyConstitution("OrthoPotential")
    skipped = clamped_cases = 0
    for eps in (1e-6, 1e-4, 1e-2):
        for stretch in ([1, 0.5, -0.3], [2, 1, -0.5], [1, 1, -1], [1, -0.5, -0.4], [2, -1, -1]):
            sigma = 1.0 + eps * np.asarray(stretch, dtype=float)
            for _ in range(3):
                A = random_rotation(rng) @ np.diag(sigma) @ random_rotation(rng).T
                q = q_of(A)
                H = c.energy(q, KAPPA, VOLUME).hessian
                Hp = c.energy(q, KAPPA, VOLUME, project_psd=True).hessian
                lam, vec = np.linalg.eigh(H)
                clamp = (vec * np.maximum(lam, 0.0)) @ vec.T
                np.testing.assert_allclose(Hp, clamp, atol=1e-9 * np.abs(lam).max())
                s1, s2 = np.sort(sigma)[:2]
                if s1**2 + s2**2 - 2.0 > 1e-9:  # every "−" mode clearly positive
                    assert np.array_equal(Hp, H)
                    skipped += 1
                elif lam.min() < -1e-12 * lam.max():
                    clamped_cases += 1
    assert skipped == 24 and clamped_cases >= 12


def test_absorbed_negative_curvature_keeps_the_exact_hessian(rng, random_rotation):
    """The simulator adds the shape Hessian to the body's mass matrix and passes half its
    smallest eigenvalue as `absorb`. Where κ v̄ times the bound 4 (1 − μ_lb) on the negative
    eigenvalues of ∇²Ψ (μ_lb: Gershgorin's lower bound on the eigenvalues of AᵀA) is within
    it, the clamp is skipped: the exact Hessian to the bit, and the bound holds (numpy's
    eigvalsh); below it, numpy's clamp as without `absorb`."""
    c = abdsim.AffineBodyConstitution("OrthoPotential")
    exact_cases = clamped_cases = 0
    for eps in (1e-7, 1e-5, 1e-3):
        for _ in range(8):
            sigma = 1.0 + eps * rng.uniform(-1.0, 0.3, 3)  # compressed: negative modes
            A = random_rotation(rng) @ np.diag(sigma) @ random_rotation(rng).T
            q = q_of(A)
            H = c.energy(q, KAPPA, VOLUME).hessian
            lam = np.linalg.eigvalsh(H)
            M = A.T @ A
            mu_lb = min(M[i, i] - sum(abs(M[i, j]) for j in range(3) if j != i) for i in range(3))
            bound = KAPPA * VOLUME * 4.0 * max(0.0, 1.0 - mu_lb)
            assert lam.min() >= -bound * (1 + 1e-9) - 1e-9 * lam.max()
            if lam.min() > -1e-12 * lam.max():
                continue  # nothing to clamp at this sample
            # 1.01 and 0.99: clear of the last bits of the bound as C++ computes it
            big = c.energy(q, KAPPA, VOLUME, project_psd=True, absorb=1.01 * bound).hessian
            assert np.array_equal(big, H)
            exact_cases += 1
            small = c.energy(q, KAPPA, VOLUME, project_psd=True, absorb=0.99 * bound).hessian
            lam_h, vec = np.linalg.eigh(H)
            clamp = (vec * np.maximum(lam_h, 0.0)) @ vec.T
            np.testing.assert_allclose(small, clamp, atol=1e-9 * np.abs(lam_h).max())
            assert not np.array_equal(small, H)
            clamped_cases += 1
    assert exact_cases == clamped_cases >= 20
    with pytest.raises(ValueError, match="absorb"):
        c.energy(np.r_[0, 0, 0, np.eye(3).ravel()], KAPPA, VOLUME, True, absorb=-1.0)
