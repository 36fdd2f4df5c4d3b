"""The IPC contact energy term on affine bodies: derivatives in body coordinates (12 per body)
vs finite differences, PSD Hessians, the ground, CCD step bounds, initial checks, friction,
contact tables, fixed bodies, adaptive stiffness and determinism."""

import subprocess
import sys

import numpy as np
import pytest

from abdsim._native import _core

D_HAT = 0.02


def stacked_boxes(scenes, rng, n=3, gap=0.002, affine=0.005):
    """n unit boxes stacked along z with small rotations, affine distortions and gaps < d̂."""
    V, F = scenes.box()
    qs, z = [], 0.0
    for _ in range(n):
        A = scenes.rotation(rng, angle=0.01) @ (np.eye(3) + affine * rng.normal(size=(3, 3)))
        lo, hi = (V @ A.T)[:, 2].min(), (V @ A.T)[:, 2].max()
        p = np.array([rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), z - lo])
        qs.append(scenes.q_of(p, A))
        z = z - lo + hi + gap
    return [{"V": V, "F": F}], [0] * n, np.stack(qs)


@pytest.fixture
def stack(scenes, rng):
    return stacked_boxes(scenes, rng)


def test_active_pairs_and_value_are_finite(scenes, stack):
    geoms, body_geometry, q = stack
    term = scenes.term(geoms, body_geometry, q, d_hat=D_HAT, kappa=1e4)
    term.check_initial(q)
    term.update(q)
    counts = term.counts()
    assert counts["point_triangle"] > 0 and counts["edge_edge"] > 0
    assert 0 < term.value(q) < np.inf
    assert 0 < term.min_distance(q) < D_HAT


def test_gradient_vs_finite_differences(scenes, fd, stack):
    geoms, body_geometry, q = stack
    term = scenes.term(geoms, body_geometry, q, d_hat=D_HAT, kappa=1e4)
    term.update(q)
    x = q.ravel()
    g = term.gradient(x)
    g_fd = fd.gradient(term.value, x, h=1e-7)
    np.testing.assert_allclose(g, g_fd, rtol=1e-5, atol=1e-6 * np.abs(g).max())
    assert np.abs(g).max() > 0


def test_exact_hessian_vs_finite_differences(scenes, fd, stack):
    geoms, body_geometry, q = stack
    term = scenes.term(geoms, body_geometry, q, d_hat=D_HAT, kappa=1e4, project_hessian=False)
    x = q.ravel()
    H = term.hessian(x)
    H_fd = fd.jacobian(term.gradient, x, h=1e-7)
    np.testing.assert_allclose(H, H_fd, rtol=1e-4, atol=1e-5 * np.abs(H).max())
    np.testing.assert_allclose(H, H.T, atol=1e-9 * np.abs(H).max())


def test_projected_hessian_is_psd_and_blocks(scenes, stack):
    geoms, body_geometry, q = stack
    term = scenes.term(geoms, body_geometry, q, d_hat=D_HAT, kappa=1e4)
    H = term.hessian(q)
    eig = np.linalg.eigvalsh(0.5 * (H + H.T))
    assert eig.min() >= -1e-9 * eig.max()
    np.testing.assert_allclose(H, H.T, atol=1e-9 * np.abs(H).max())
    exact = scenes.term(geoms, body_geometry, q, d_hat=D_HAT, kappa=1e4, project_hessian=False)
    assert np.linalg.eigvalsh(exact.hessian(q)).min() < -1e-6 * eig.max()  # projection mattered
    # blocks: only neighbours in the stack couple; each (row, col) appears once
    keys = [(r, c) for r, c, _ in term.hessian_blocks(q)]
    assert len(keys) == len(set(keys))
    assert set(keys) <= {(i, j) for i in range(3) for j in range(3) if abs(i - j) <= 1}
    assert (0, 1) in keys and (1, 0) in keys


def test_thickness_shells(scenes, fd, rng):
    # two square shells (two triangles each) with thickness radius r: contact at gap d − 2r
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float) - [0.5, 0.5, 0]
    F = np.array([[0, 1, 2], [0, 2, 3]], np.int32)
    r = 0.01
    geom = {"V": V, "F": F, "r": np.full(4, r)}
    c, s = np.cos(0.3), np.sin(0.3)
    A = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ scenes.rotation(rng, angle=0.003)
    q = np.stack([scenes.q_of([0, 0, 0]), scenes.q_of([0.1, 0.05, 2 * r + 0.005], A)])
    term = scenes.term([geom], [0, 0], q, d_hat=D_HAT, kappa=1e4)
    term.check_initial(q)
    term.update(q)
    assert term.counts()["point_triangle"] > 0
    gap = term.min_distance(q)
    assert 0 < gap < 0.005 + 1e-12
    x = q.ravel()
    np.testing.assert_allclose(
        term.gradient(x), fd.gradient(term.value, x, h=1e-8), rtol=1e-5, atol=1e-6
    )
    # closer than 2r is an invalid start even though the surfaces do not touch
    q_bad = q.copy()
    q_bad[1, 2] = 1.5 * r
    with pytest.raises(ValueError, match="bodies 0 and 1"):
        term.check_initial(q_bad)
    assert term.value(q_bad) == np.inf


def test_rods_edge_edge_analytic(scenes, contact):
    # two perpendicular rods of radius r crossing at centre distance 2r + g
    r, g, kappa = 0.005, 0.004, 1e4
    V = np.array([[-1, 0, 0], [0, 0, 0], [1, 0, 0]], float)
    E = np.array([[0, 1], [1, 2]], np.int32)
    geom = {"V": V, "E": E, "r": np.full(3, r)}
    Rz = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]], float)
    q = np.stack([scenes.q_of([0.3, 0, 0]), scenes.q_of([0, 0.2, 2 * r + g], Rz)])
    term = scenes.term([geom], [0, 0], q, d_hat=D_HAT, kappa=kappa)
    term.update(q)
    assert term.counts()["edge_edge"] == 1
    d = 2 * r + g
    assert term.value(q) == pytest.approx(kappa * contact.barrier(d * d, D_HAT, 2 * r), rel=1e-10)
    # the force is along z, equal and opposite on the two rods
    gz = term.gradient(q).reshape(2, 12)[:, 2]
    expected = kappa * contact.barrier_first_derivative(d * d, D_HAT, 2 * r) * 2 * d
    np.testing.assert_allclose(gz, [-expected, expected], rtol=1e-10)


def test_ground_half_space(scenes, contact, fd):
    V, F = scenes.box((0.2, 0.2, 0.2))
    h, gap, kappa = -0.3, 0.004, 1e4
    q = np.stack([scenes.q_of([0, 0, h + 0.1 + gap])])
    term = scenes.term(
        [{"V": V, "F": F}], [0], q, d_hat=D_HAT, kappa=kappa, ground=True, ground_height=h
    )
    term.check_initial(q)
    term.update(q)
    assert term.counts()["point_ground"] == 4
    assert term.min_distance(q) == pytest.approx(gap)
    assert term.value(q) == pytest.approx(4 * kappa * contact.barrier(gap**2, D_HAT), rel=1e-10)
    g = term.gradient(q)
    assert g[2] == pytest.approx(
        4 * kappa * contact.barrier_first_derivative(gap**2, D_HAT) * 2 * gap, rel=1e-10
    )
    np.testing.assert_allclose(
        g, fd.gradient(term.value, q.ravel(), h=1e-8), rtol=1e-5, atol=1e-6 * abs(g[2])
    )
    # falling 1 cm: the step stops at 90 % of the way to the ground
    dq = np.zeros(12)
    dq[2] = -0.01
    assert term.max_step(q, dq) == pytest.approx(0.9 * gap / 0.01, rel=1e-12)
    # into the ground: invalid start naming the body
    with pytest.raises(ValueError, match="body 0"):
        term.check_initial(q - np.eye(12)[2] * 0.01)


def test_max_step_is_safe_for_random_motions(scenes, rng):
    """Never beyond the first impact: every configuration up to the bound is valid, and the
    bound is below the collision-free step of ipctk's Tight-Inclusion CCD on the same linear
    vertex trajectories (ipctk rescales its time of impact by 0.8)."""
    import ipctk

    # bodies on a line, 0.55 apart (a 0.3 box spans at most 0.52): a valid start; random
    # motions of ~0.3 then often collide
    V, F = scenes.box((0.3, 0.3, 0.3))
    n, limited = 5, 0
    for _ in range(6):
        q = np.stack(
            [
                scenes.q_of([0.55 * i, *rng.uniform(-0.01, 0.01, 2)], scenes.rotation(rng))
                for i in range(n)
            ]
        )
        term = scenes.term([{"V": V, "F": F}], [0] * n, q, d_hat=D_HAT, kappa=1e4)
        term.check_initial(q)
        dq = rng.normal(0, 0.3, size=q.shape)
        dq[:, 3:] *= 0.3
        alpha = term.max_step(q, dq)
        assert 0 < alpha <= 1
        for t in np.linspace(0, alpha, 30):
            term.check_initial(q + t * dq)  # never intersecting up to the step bound
        X0, X1 = term.world_vertices(q), term.world_vertices(q + dq)
        mesh = ipctk.CollisionMesh(
            np.asfortranarray(X0),
            np.asfortranarray(np.array(term.edges, np.int32)),
            np.asfortranarray(np.array(term.faces, np.int32)),
        )
        reference = ipctk.compute_collision_free_stepsize(
            mesh, np.asfortranarray(X0), np.asfortranarray(X1)
        )
        assert alpha <= reference / 0.8 + 1e-6
        limited += alpha < 1
    assert limited >= 3


def test_check_initial_names_intersecting_bodies(scenes):
    V, F = scenes.box()
    q = np.stack(
        [scenes.q_of([5, 0, 0]), scenes.q_of([0, 0, 0]), scenes.q_of([0.5, 0.5, 0.5], np.eye(3))]
    )
    term = scenes.term([{"V": V, "F": F}], [0, 0, 0], q)
    with pytest.raises(ValueError, match="bodies 1 and 2 intersect"):
        term.check_initial(q)
    # separated: fine
    q[2, :3] = [0, 0, 1.5]
    term.check_initial(q)
    # a small box deep inside a face (no vertex–triangle contact): edges cross triangles
    Vs, Fs = scenes.box((0.2, 0.2, 3.0))
    q2 = np.stack([scenes.q_of([0, 0, 0]), scenes.q_of([0, 0, 0])])
    term2 = scenes.term([{"V": V, "F": F}, {"V": Vs, "F": Fs}], [0, 1], q2)
    with pytest.raises(ValueError, match="bodies 0 and 1 intersect"):
        term2.check_initial(q2)


def brute_force_pairs(term, q, d_hat, r, ipctk):
    X = term.world_vertices(q)
    faces, edges = np.array(term.faces), np.array(term.edges)
    vb = np.repeat(np.arange(len(term.vertex_offsets) - 1), np.diff(term.vertex_offsets))
    pt, ee = set(), set()
    for v in range(len(X)):
        for f, (a, b, c) in enumerate(faces):
            if vb[v] == vb[a]:
                continue
            d = np.sqrt(ipctk.point_triangle_distance(X[v], X[a], X[b], X[c]))
            if d - r[v] - max(r[a], r[b], r[c]) < d_hat:
                pt.add((v, f))
    for i, (a0, a1) in enumerate(edges):
        for j in range(i + 1, len(edges)):
            b0, b1 = edges[j]
            if vb[a0] == vb[b0]:
                continue
            d = np.sqrt(ipctk.edge_edge_distance(X[a0], X[a1], X[b0], X[b1]))
            if d - max(r[a0], r[a1]) - max(r[b0], r[b1]) < d_hat:
                ee.add((i, j))
    return pt, ee


def test_broad_phase_matches_brute_force(scenes, rng):
    import ipctk

    V, F = scenes.box((0.3, 0.2, 0.25))
    n, found = 6, 0
    for _ in range(4):
        # clustered bodies, with thickness on some, so that many pairs are within reach
        q = np.stack(
            [scenes.q_of(rng.uniform(-0.3, 0.3, 3), scenes.rotation(rng)) for _ in range(n)]
        )
        thick = rng.uniform(0, 0.01, len(V))
        geoms = [{"V": V, "F": F}, {"V": V, "F": F, "r": thick}]
        bg = [0, 1, 0, 1, 0, 1]
        term = scenes.term(geoms, bg, q, d_hat=0.05, kappa=1.0)
        term.update(q)
        r = np.concatenate([thick if g == 1 else np.zeros(len(V)) for g in bg])
        pt, ee = brute_force_pairs(term, q, 0.05, r, ipctk)
        got = term.active_pairs()
        assert {tuple(p) for p in got["point_triangle"]} == pt
        assert {tuple(p) for p in got["edge_edge"]} == ee
        found += len(pt) + len(ee)
    assert found > 50


def test_self_collision_flag(scenes):
    # one body made of two parallel squares 1 cm apart: only self-collision sees the pairs
    sq = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    V = np.vstack([sq, sq + [0.1, 0.1, 0.01]])
    F = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]], np.int32)
    q = np.stack([scenes.q_of([0, 0, 0])])
    off = scenes.term([{"V": V, "F": F, "self": 0}], [0], q, d_hat=D_HAT, kappa=1.0)
    on = scenes.term([{"V": V, "F": F, "self": 1}], [0], q, d_hat=D_HAT, kappa=1.0)
    off.update(q)
    on.update(q)
    assert sum(off.counts()[k] for k in ("point_triangle", "edge_edge")) == 0
    got = on.active_pairs()["point_triangle"]
    assert len(got) > 0
    for v, f in got:  # never a vertex against its own triangle
        assert v not in on.faces[f]
    assert on.min_distance(q) == pytest.approx(0.01)


def test_friction(scenes, fd, contact):
    # a box resting 5 mm above the ground, then sliding by a tangential displacement
    V, F = scenes.box((0.2, 0.2, 0.2))
    gap, kappa, mu, dt = 0.005, 1e4, 0.4, 0.01
    q_t = np.stack([scenes.q_of([0, 0, 0.1 + gap])])
    setup = dict(d_hat=D_HAT, kappa=kappa, ground=True, mu=mu, eps_v=1e-3, dt=dt)
    term = scenes.term([{"V": V, "F": F}], [0], q_t, **setup)
    term.begin_step(q_t, dt)
    assert term.counts()["friction"] == 4
    lam = contact.barrier_force_magnitude(gap**2, D_HAT, 0.0, kappa)
    eps = 1e-3 * dt
    for slide in [0.3 * eps, 5 * eps]:  # static (smoothed) and sliding regimes
        q = q_t.copy()
        q[0, 0] += slide
        assert term.friction_value(q) == pytest.approx(
            4 * mu * lam * contact.smooth_friction_f0(slide, eps), rel=1e-10
        )
        g = term.gradient(q) - term.gradient(q_t)  # the barrier part does not change
        expected = 4 * mu * lam * contact.smooth_friction_f1(slide, eps)
        assert g[0] == pytest.approx(expected, rel=1e-8)
        x = q.ravel()
        np.testing.assert_allclose(
            term.gradient(x),
            fd.gradient(term.value, x, h=1e-9),
            rtol=1e-5,
            atol=1e-7 * np.abs(term.gradient(x)).max(),
        )
    # μ per pair from the contact table: ground element 1 against body element 0 has μ = 0.1
    s = contact.ContactSettings()
    for key, value in setup.items():
        if key != "dt":
            setattr(s, key, value)
    s.ground_contact_element = 1
    s.set_contact_table(lambda a, b: contact.ContactRule(True, 0.1 if (a, b) == (0, 1) else mu))
    term2 = contact.IpcContactTerm([V], [F], [], [], [0], [0], q_t, settings=s, dt=dt)
    term2.begin_step(q_t, dt)
    q = q_t.copy()
    q[0, 0] += 5 * eps
    assert term2.friction_value(q) == pytest.approx(term.friction_value(q) * 0.1 / mu, rel=1e-12)


def test_friction_hessian_psd_and_exact(scenes, fd, rng):
    geoms, bg, q_t = stacked_boxes(scenes, rng, n=2, gap=0.005)
    term = scenes.term(
        geoms, bg, q_t, d_hat=D_HAT, kappa=1e4, mu=0.5, project_hessian=False, dt=0.01
    )
    term.begin_step(q_t, 0.01)
    assert term.counts()["friction"] > 0
    q = q_t.copy()
    q[1, :2] += [2e-5, -1e-5]  # slide the top box by a few ε_v h
    x = q.ravel()
    H = term.hessian(x)
    np.testing.assert_allclose(
        H, fd.jacobian(term.gradient, x, h=1e-9), rtol=1e-4, atol=1e-5 * np.abs(H).max()
    )
    friction_only = term.hessian(x) - scenes.term(
        geoms, bg, q_t, d_hat=D_HAT, kappa=1e4, project_hessian=False
    ).hessian(x)
    assert np.linalg.eigvalsh(friction_only).min() >= -1e-9 * np.abs(friction_only).max()


def test_contact_table_and_fixed_bodies(scenes, rng):
    geoms, bg, q = stacked_boxes(scenes, rng, n=3)
    base = scenes.term(geoms, bg, q, d_hat=D_HAT, kappa=1e4)
    base.update(q)
    n_base = base.counts()["point_triangle"]
    # elements: body 0 -> 0, body 1 -> 1, body 2 -> 2; elements 1 and 2 never collide
    s = contact_settings(D_HAT, 1e4)
    s.body_contact_element = [0, 1, 2]
    s.set_contact_table(lambda a, b: (not (a == 1 and b == 2), 0.5))
    term = _core.contact.IpcContactTerm(
        [geoms[0]["V"]], [geoms[0]["F"]], [], [], [0], bg, q, settings=s
    )
    term.update(q)
    bodies = {tuple(sorted((blk[0], blk[1]))) for blk in term.hessian_blocks(q)}
    assert (1, 2) not in bodies and (0, 1) in bodies
    assert 0 < term.counts()["point_triangle"] < n_base
    # the same through matrices
    s.set_contact_table_matrices(np.array([[1, 1, 1], [1, 1, 0], [1, 0, 1]]), np.full((3, 3), 0.5))
    term = _core.contact.IpcContactTerm(
        [geoms[0]["V"]], [geoms[0]["F"]], [], [], [0], bg, q, settings=s
    )
    assert {tuple(sorted((b[0], b[1]))) for b in term.hessian_blocks(q)} == bodies
    # fixed bodies still collide with moving ones, but two fixed bodies are ignored
    fixed = scenes.term(geoms, bg, q, is_fixed=[True, True, False], d_hat=D_HAT, kappa=1e4)
    keys = {tuple(sorted((b[0], b[1]))) for b in fixed.hessian_blocks(q)}
    assert (1, 2) in keys and (0, 1) not in keys


def contact_settings(d_hat, kappa):
    s = _core.contact.ContactSettings()
    s.d_hat, s.kappa = d_hat, kappa
    return s


def test_adaptive_kappa(scenes, contact, stack):
    geoms, bg, q = stack
    mass = [2.0, 3.0, 4.0]
    term = scenes.term(geoms, bg, q, mass=mass, d_hat=D_HAT, kappa=0.0, dt=0.01)
    assert term.adaptive_kappa
    # κ_min is IPC's, measured against 1e3 d̂ instead of the scene's size (scale-free)
    assert term.stiffness_length == pytest.approx(1e3 * D_HAT)
    kmin = contact.min_barrier_stiffness(term.stiffness_length, D_HAT, 3.0, 0.01)
    assert term.kappa == pytest.approx(kmin)
    # gradient balance: a rest gradient that exactly cancels 7 κ_min ∇B₁ gives 7 κ_min
    term.kappa = 1.0
    grad_b1 = term.gradient(q)
    kappa = term.initialize_kappa(q, -7 * kmin * 0.01**2 * grad_b1)
    assert kappa == pytest.approx(7 * kmin, rel=1e-9)
    assert term.stiffness_bounds() == pytest.approx((7 * kmin, kmin, 100 * kmin))


DETERMINISM_SCRIPT = """
import hashlib, numpy as np, sys
sys.path.insert(0, {tests!r})
from conftest import Scenes
rng = np.random.default_rng(7)
V, F = Scenes.box((0.3, 0.3, 0.3))
grid = [(0.32 * (i % 4), 0.32 * (i // 4), 0.0) for i in range(8)]
q = np.stack([Scenes.q_of(c, Scenes.rotation(rng, angle=0.02)) for c in grid])
term = Scenes.term([{{"V": V, "F": F}}], [0] * 8, q, d_hat=0.05, kappa=1e4, mu=0.5)
term.check_initial(q)
term.begin_step(q, 0.01)
x = q.ravel() + 1e-4 * rng.normal(size=q.size)
h = hashlib.sha256()
dq = rng.normal(size=x.size)
for a in (term.value(x), term.gradient(x), term.hessian(x), term.max_step(x, dq)):
    h.update(np.ascontiguousarray(a).tobytes())
print(h.hexdigest(), term.counts()["point_triangle"])
"""


def test_bit_identical_across_runs_and_threads(tmp_path):
    import os
    import pathlib

    tests = str(pathlib.Path(__file__).parent)
    script = tmp_path / "det.py"
    script.write_text(DETERMINISM_SCRIPT.format(tests=tests))
    outputs = []
    for threads in ["1", "2", "2", "3"]:
        env = dict(os.environ, OMP_NUM_THREADS=threads)
        out = subprocess.run(
            [sys.executable, "-P", str(script)],
            env=env,
            capture_output=True,
            text=True,
            check=True,
            cwd=tmp_path,
        )
        outputs.append(out.stdout.strip())
    assert len(set(outputs)) == 1, outputs
    assert int(outputs[0].split()[1]) > 64  # enough stencils for the parallel path


def test_invalid_input_raises(scenes, contact):
    V, F = scenes.box()
    q = np.stack([scenes.q_of([0, 0, 0])])
    with pytest.raises(ValueError, match="geometry 1 of 1"):
        contact.IpcContactTerm([V], [F], [], [], [0], [1], q)
    with pytest.raises(ValueError, match="a triangle refers to vertex 8"):
        contact.IpcContactTerm([V], [np.array([[0, 1, 8]], np.int32)], [], [], [0], [0], q)
    with pytest.raises(ValueError, match="thickness has 3 values for 8 vertices"):
        contact.IpcContactTerm([V], [F], [], [np.ones(3)], [0], [0], q)
    term = contact.IpcContactTerm([V], [F], [], [], [0], [0], q)
    with pytest.raises(ValueError, match="expected 12 x 1"):
        term.value(np.zeros(5))
    s = contact.ContactSettings()
    s.d_hat = 0.0
    with pytest.raises(ValueError, match="d_hat"):
        contact.IpcContactTerm([V], [F], [], [], [0], [0], q, settings=s)
    # no bodies at all is a valid (empty) scene
    empty = contact.IpcContactTerm([], [], [], [], [], [], np.zeros((0, 12)))
    assert empty.value(np.zeros(0)) == 0.0 and empty.max_step(np.zeros(0), np.zeros(0)) == 1.0
