"""Fuzz of the public API and the _core entry points (hypothesis, fixed seed, bounded budget).

Every call either raises a clear exception (ValueError, IndexError, TypeError) or returns
finite results, and then only for valid input: no crash, no silent acceptance of NaN/inf,
out-of-range indices, short arrays or degenerate transforms.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import abdsim
from abdsim._native import _core

FUZZ = settings(
    max_examples=120,
    derandomize=True,  # a fixed sequence of examples: the same run in CI every time
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)
REFUSED = (ValueError, IndexError, TypeError)

values = st.one_of(
    st.floats(-2.0, 2.0, allow_nan=False),
    st.sampled_from([np.nan, np.inf, -np.inf, 0.0, 1e300]),
)


@st.composite
def meshes(draw, arity: int):
    """Vertices (some maybe non-finite), cells (indices maybe out of range), thickness."""
    nv = draw(st.integers(1, 6))
    flat = draw(st.lists(values, min_size=3 * nv, max_size=3 * nv))
    V = np.array(flat, dtype=np.float64).reshape(nv, 3)
    nc = draw(st.integers(0, 4))
    idx = draw(st.lists(st.integers(-2, nv + 2), min_size=arity * nc, max_size=arity * nc))
    C = np.array(idx, dtype=np.int32).reshape(nc, arity)
    nr = draw(st.sampled_from([nv, nv, nv - 1, nv + 1, 0]))
    r = np.array(draw(st.lists(values, min_size=nr, max_size=nr)), dtype=np.float64)
    return V, C, r


def _valid(V, C, r=None) -> bool:
    ok = np.isfinite(V).all() and (C.size == 0 or (C.min() >= 0 and C.max() < len(V)))
    if r is not None:
        ok = ok and r.shape == (len(V),) and np.isfinite(r).all() and (r > 0).all()
    return bool(ok)


def _finite(result) -> bool:
    return all(np.isfinite(np.asarray(x, dtype=np.float64)).all() for x in result)


@FUZZ
@given(meshes(4), st.sampled_from([1e3, 0.0, np.nan]))
def test_tet_mesh_mass(mesh, rho):
    V, T, _ = mesh
    try:
        out = _core.tet_mesh_mass(V, T, rho)
    except REFUSED:
        return
    assert _valid(V, T) and rho > 0 and _finite(out)


@FUZZ
@given(meshes(3), st.booleans())
def test_surface_and_shell_mass(mesh, shell):
    V, F, r = mesh
    try:
        out = _core.shell_mass(V, F, r, 1e3) if shell else _core.closed_surface_mass(V, F, 1e3)
    except REFUSED:
        return
    assert _valid(V, F, r if shell else None) and _finite(out)


@FUZZ
@given(meshes(2))
def test_rod_mass(mesh):
    V, E, r = mesh
    try:
        out = _core.rod_mass(V, E, r, 1e3)
    except REFUSED:
        return
    assert _valid(V, E, r) and _finite(out)


@FUZZ
@given(meshes(3), st.integers(-1, 2), st.lists(values, min_size=12, max_size=12))
def test_scene_data_and_world(mesh, geometry, q):
    V, F, r = mesh
    data = _core.SceneData()
    try:
        g = data.add_geometry(V, F, np.zeros((0, 2), np.int32), np.abs(r), 0, 3)
    except REFUSED:
        assert not _valid(V, F) or len(r) != len(V) or not np.isfinite(r).all()
        return
    assert _valid(V, F) and g == 0
    q = np.array(q)[None]
    ones = np.ones(1, dtype=np.int32)
    try:
        data.add_bodies(
            geometry, q, np.zeros((1, 12)), 1.0, np.zeros(3), np.eye(3) * 0.1, np.full(1, 1e8),
            1.0, 1, 0 * ones, ones, 0 * ones,
        )  # fmt: skip
        world = _core.World(data)
    except REFUSED:
        return
    assert geometry == 0 and np.isfinite(q).all()
    world.step(1)
    assert np.isfinite(world.q).all()


@FUZZ
@given(meshes(3), st.lists(values, min_size=12, max_size=12), st.integers(-1, 1))
def test_contact_term(mesh, q, body_geometry):
    V, F, r = mesh
    q = np.array(q)
    try:
        term = _core.contact.IpcContactTerm([V], [F], [], [np.abs(r)], [0], [body_geometry], q)
        value = term.value(q)
    except REFUSED:
        return
    assert _valid(V, F) and np.isfinite(q).all() and body_geometry == 0
    assert np.isfinite(value)


@FUZZ
@given(st.lists(values, min_size=0, max_size=30), st.booleans())
def test_shape_energy_term_checks_q(q, as_energy_term):
    data = _core.SceneData()
    g = data.add_geometry(np.eye(3), np.zeros((0, 3), np.int32), np.array([[0, 1]], np.int32),
                          np.ones(3), 0, 1)  # fmt: skip
    ones = np.ones(2, dtype=np.int32)
    q0 = np.tile(np.r_[np.zeros(3), np.eye(3).ravel()], (2, 1))
    data.add_bodies(
        g, q0, 0 * q0, 1.0, np.zeros(3), np.eye(3), np.full(2, 1e8), 1.0, 1, 0 * ones, ones,
        0 * ones,
    )  # fmt: skip
    term = _core.ShapeEnergyTerm(data)
    q = np.array(q, dtype=np.float64)
    try:
        value = term.value(q) if as_energy_term else term.gradient(q)
    except REFUSED:
        return
    assert q.shape == (24,) and np.isfinite(q).all() and np.isfinite(value).all()


# -- the public API -----------------------------------------------------------------------
@FUZZ
@given(
    st.sampled_from(["dt", "contact", "friction", "newton_max_iterations", "project_psd"]),
    st.one_of(
        st.booleans(),
        st.text(max_size=3),
        st.none(),
        values,
        st.integers(-3, 3),
        st.sampled_from([np.float32(0.01), np.int64(5), np.bool_(True)]),
    ),
)
def test_scene_settings(name, value):
    try:
        scene = abdsim.Scene(**{name: value})
    except REFUSED:
        return
    v = getattr(scene.settings, name)
    if name in ("contact", "project_psd"):
        assert isinstance(v, bool | np.bool_)
    else:
        assert not isinstance(v, bool | np.bool_ | str) and np.isfinite(v)


def _box_world():
    scene = abdsim.Scene(gravity=(0.0, 0.0, 0.0))
    for x in (0.0, 0.5):
        sc = abdsim.geometry.box(0.2)
        abdsim.AffineBodyConstitution().apply_to(sc, 1e8)
        T = np.eye(4)
        T[0, 3] = x
        sc.transforms = T
        scene.add(sc)
    return abdsim.World(scene)


WORLD = None


@FUZZ
@given(st.lists(values, min_size=9, max_size=9), st.lists(values, min_size=3, max_size=3))
def test_world_set_state_and_targets(A, p):
    global WORLD
    WORLD = WORLD or _box_world()
    T = WORLD.transforms()
    T[1, :3, :3] = np.array(A).reshape(3, 3)
    T[1, :3, 3] = p
    Ab = T[1, :3, :3]
    proper = np.isfinite(T).all() and np.linalg.det(Ab) > 0
    if proper:
        sv = np.linalg.svd(Ab, compute_uv=False)
        proper = sv[-1] > 1e-6 * sv[0]
    for call in (
        lambda: WORLD.set_kinematic_target(1, T[1]),
        lambda: WORLD.set_state(T),
    ):
        before = WORLD.q
        try:
            call()
        except REFUSED:
            np.testing.assert_array_equal(WORLD.q, before)
            continue
        assert proper
    WORLD = None  # a fresh world next time (the targets made body 1 kinematic)


@FUZZ
@given(st.one_of(values, st.integers(-2, 3), st.booleans(), st.text(max_size=2)))
def test_world_step_count(n):
    world = _box_world()
    try:
        world.step(n)
    except REFUSED:
        assert world.step_count == 0
        return
    assert world.step_count == n and isinstance(n, int | float) and not isinstance(n, bool)


@FUZZ
@given(meshes(3), st.sampled_from(["shell", "solid"]), values)
def test_geometry_and_constitutions(mesh, kind, thickness):
    V, F, _ = mesh
    try:
        sc = abdsim.geometry.triangle_mesh(V, F)
        if kind == "shell":
            abdsim.AffineBodyShell().apply_to(sc, 1e8, thickness=thickness)
        else:
            abdsim.AffineBodyConstitution().apply_to(sc, 1e8)
    except REFUSED:
        return
    assert _valid(V, F) and (kind == "solid" or thickness > 0 and np.isfinite(thickness))
    assert np.isfinite(float(sc.meta["volume"])) and float(sc.meta["volume"]) > 0


def test_the_fuzz_saw_both_outcomes():
    """Guard against a fuzz that only ever hits one branch: valid input still succeeds."""
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    m, _, _ = _core.tet_mesh_mass(V, np.array([[0, 1, 2, 3]], np.int32), 6.0)
    assert m == pytest.approx(1.0)
    with pytest.raises(IndexError):
        _core.tet_mesh_mass(V, np.array([[0, 1, 2, 4]], np.int32), 6.0)


CONTACT_FIELDS = ["d_hat", "kappa", "mu", "eps_v", "ground_height", "ccd_target"]
SOLVER_FIELDS = ["tol_translation", "tol_affine", "armijo_c", "ccd_safety", "pcg_tolerance"]


@FUZZ
@given(st.sampled_from(CONTACT_FIELDS + SOLVER_FIELDS), values)
def test_core_settings_refuse_non_finite_values(name, value):
    s = _core.contact.ContactSettings() if name in CONTACT_FIELDS else _core.SolverSettings()
    try:
        setattr(s, name, value)
    except REFUSED:
        assert not np.isfinite(value)
        return
    assert np.isfinite(value) and getattr(s, name) == value


@FUZZ
@given(
    st.lists(values, min_size=24, max_size=24),
    st.sampled_from(["point_triangle", "edge_edge"]),
    st.sampled_from([0.0, 0.1, 1.0, np.nan]),
)
def test_ccd_and_distances_refuse_non_finite_points(coords, kind, target):
    x = np.array(coords).reshape(8, 3)
    ccd = getattr(_core.contact, f"{kind}_ccd")
    distance = getattr(_core.contact, f"{kind}_distance")
    try:
        toi = ccd(*x, target=target)
    except REFUSED:
        assert not (np.isfinite(x).all() and 0 < target < 1)
    else:
        assert np.isfinite(x).all() and 0.0 <= toi <= 1.0
    try:
        d2 = distance(*x[:4])
    except REFUSED:
        assert not np.isfinite(x[:4]).all()
    else:
        assert np.isfinite(x[:4]).all() and d2 >= 0
