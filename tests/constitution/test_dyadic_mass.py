"""Dyadic mass against closed forms, trimesh's exact polyhedral integrals and tet meshes."""

import numpy as np
import pytest
import trimesh

import abdsim

RHO = 1000.0


def solid(mesh: trimesh.Trimesh, rho: float = RHO):
    sc = abdsim.geometry.from_trimesh(mesh)
    abdsim.AffineBodyConstitution().apply_to(sc, kappa=1e8, mass_density=rho)
    return sc


def rel(a, b):
    return np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(np.max(np.abs(b)), 1e-300)


def test_box_closed_form():
    a, b, c = 0.3, 0.5, 0.7
    mesh = trimesh.creation.box(extents=(a, b, c))
    mesh.apply_translation([1.0, -2.0, 3.0])
    sc = solid(mesh)
    m = RHO * a * b * c
    rb = abdsim.to_rigid_body(sc)
    assert rel(rb.mass, m) < 1e-12
    assert rel(rb.mass_center, [1.0, -2.0, 3.0]) < 1e-12
    expected = m / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    assert rel(rb.inertia, expected) < 1e-10
    assert sc.meta["volume"] == pytest.approx(a * b * c, rel=1e-12)
    assert sc.meta["mass"] == sc.meta["abd_mass"]
    # S about the origin: ∫ρ x x^T for the translated box
    c0 = np.array([1.0, -2.0, 3.0])
    s_expected = m * np.diag([a * a, b * b, c * c]) / 12 + m * np.outer(c0, c0)
    assert rel(sc.meta["abd_mass_x_bar_x_bar"], s_expected) < 1e-10


def test_sphere_and_cylinder_converge_to_closed_forms():
    r, h = 0.2, 0.6
    sph = abdsim.to_rigid_body(solid(trimesh.creation.icosphere(subdivisions=5, radius=r)))
    m = RHO * 4 / 3 * np.pi * r**3
    assert rel(sph.mass, m) < 2e-3
    assert rel(np.diag(sph.inertia), np.full(3, 0.4 * m * r * r)) < 5e-3
    cyl = abdsim.to_rigid_body(solid(trimesh.creation.cylinder(radius=r, height=h, sections=256)))
    m = RHO * np.pi * r * r * h
    expected = [m * (3 * r * r + h * h) / 12, m * (3 * r * r + h * h) / 12, m * r * r / 2]
    assert rel(cyl.mass, m) < 1e-3
    assert rel(np.diag(cyl.inertia), expected) < 2e-3


@pytest.mark.parametrize(
    "mesh",
    [
        trimesh.creation.torus(0.5, 0.2),
        trimesh.creation.annulus(0.2, 0.5, 0.3),
        trimesh.creation.icosphere(subdivisions=2, radius=0.4),
        trimesh.creation.capsule(height=0.5, radius=0.1, count=[12, 12]),
    ],
    ids=["torus", "annulus", "icosphere", "capsule"],
)
def test_matches_trimesh_mass_properties(mesh):
    mesh = mesh.copy()
    rot = trimesh.transformations.random_rotation_matrix(rand=np.array([0.1, 0.7, 0.3]))
    rot[:3, 3] = [0.4, -0.2, 5.0]
    mesh.apply_transform(rot)
    sc = solid(mesh)
    props = mesh.mass_properties
    ref_mass = props.volume * RHO
    rb = abdsim.to_rigid_body(sc)
    assert rel(rb.mass, ref_mass) < 1e-9
    assert rel(rb.mass_center, props.center_mass) < 1e-9
    assert rel(rb.inertia, np.asarray(props.inertia) * RHO) < 1e-9


def star_tetrahedralize(mesh: trimesh.Trimesh):
    """Tets from the centroid to every face of a star-shaped, outward-oriented surface."""
    v = np.vstack([mesh.vertices, mesh.vertices.mean(axis=0)])
    c = len(v) - 1
    tets = np.column_stack([np.full(len(mesh.faces), c), mesh.faces])
    return v, tets


def test_tet_mesh_agrees_with_its_surface():
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=0.3)
    mesh.apply_translation([0.3, 0.1, -0.2])
    v, tets = star_tetrahedralize(mesh)
    tet_sc = abdsim.geometry.tet_mesh(v, tets)
    abdsim.AffineBodyConstitution().apply_to(tet_sc, kappa=1e8, mass_density=RHO)
    surf_sc = solid(mesh)
    for key in ("abd_mass", "abd_mass_x_bar", "abd_mass_x_bar_x_bar", "volume"):
        assert rel(tet_sc.meta[key], surf_sc.meta[key]) < 1e-12, key


def test_cube_kuhn_tets_closed_form():
    corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=float)
    # Kuhn subdivision: the six tets along the main diagonal 0 -> 7.
    paths = [(4, 6), (4, 5), (2, 6), (2, 3), (1, 5), (1, 3)]
    tets = []
    for a, b in paths:
        t = [0, a, b, 7]
        p = corners[t]
        if np.dot(p[1] - p[0], np.cross(p[2] - p[0], p[3] - p[0])) < 0:
            t = [0, b, a, 7]
        tets.append(t)
    sc = abdsim.geometry.tet_mesh(corners, tets)
    abdsim.AffineBodyConstitution().apply_to(sc, kappa=1e8, mass_density=RHO)
    rb = abdsim.to_rigid_body(sc)
    assert rel(rb.mass, RHO) < 1e-12
    assert rel(rb.mass_center, [0.5, 0.5, 0.5]) < 1e-12
    assert rel(rb.inertia, RHO / 6 * np.eye(3)) < 1e-12


def test_shell_triangle_closed_form():
    r = 0.1
    sc = abdsim.geometry.triangle_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    abdsim.AffineBodyShell().apply_to(sc, kappa=1e8, mass_density=RHO, thickness=r)
    m = RHO * 0.5 * 0.2
    assert sc.meta["abd_mass"] == pytest.approx(m, rel=1e-14)
    np.testing.assert_allclose(sc.meta["abd_mass_x_bar"], m * np.array([1 / 3, 1 / 3, 0]))
    s = sc.meta["abd_mass_x_bar_x_bar"]
    assert s[0, 0] == pytest.approx(RHO * 0.2 / 12, rel=1e-12)
    assert s[1, 1] == pytest.approx(RHO * 0.2 / 12, rel=1e-12)
    assert s[0, 1] == pytest.approx(RHO * 0.2 / 24, rel=1e-12)
    assert s[2, 2] == pytest.approx(RHO * 0.5 * (2 * r**3 / 3), rel=1e-12)
    assert sc.meta["volume"] == pytest.approx(0.5 * 2 * r, rel=1e-14)
    assert sc.meta["is_codim"] == 1
    np.testing.assert_array_equal(sc.vertices["thickness"], [r, r, r])


def test_rod_segment_closed_form():
    r = 0.1
    sc = abdsim.geometry.edge_mesh([[0, 0, 0], [1, 0, 0]], [[0, 1]])
    abdsim.AffineBodyRod().apply_to(sc, kappa=1e8, mass_density=RHO, thickness=r)
    m = RHO * np.pi * r * r
    assert sc.meta["abd_mass"] == pytest.approx(m, rel=1e-14)
    np.testing.assert_allclose(
        sc.meta["abd_mass_x_bar_x_bar"],
        np.diag([m / 3, RHO * np.pi * r**4 / 4, RHO * np.pi * r**4 / 4]),
        rtol=1e-12,
        atol=1e-15,
    )
    assert sc.meta["volume"] == pytest.approx(np.pi * r * r, rel=1e-14)


def test_shell_of_closed_surface_approaches_thin_hollow_box():
    # A hollow unit cube with wall slab 2r: mass = 6 * 1 * 2r * rho.
    r = 1e-3
    sc = abdsim.geometry.box(1.0)
    abdsim.AffineBodyShell().apply_to(sc, kappa=1e8, mass_density=RHO, thickness=r)
    m = 6 * 2 * r * RHO
    assert sc.meta["mass"] == pytest.approx(m, rel=1e-12)
    # thin-walled hollow cube: I = (5/18) m a^2 about any axis through the centre (a = 1)
    np.testing.assert_allclose(np.diag(sc.meta["inertia"]), 5 / 18 * m, rtol=1e-5)


@pytest.mark.parametrize(
    "make",
    [
        lambda: (
            abdsim.AffineBodyShell(),
            abdsim.geometry.triangle_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]),
            {"thickness": 1e-4},
        ),
        lambda: (
            abdsim.AffineBodyRod(),
            abdsim.geometry.edge_mesh([[0, 0, 0], [1, 0, 0]], [[0, 1]]),
            {"thickness": 1e-4},
        ),
        lambda: (
            abdsim.AffineBodyRod(),
            abdsim.geometry.edge_mesh([[0, 0, 0], [1, 0, 0], [1, 1, 0]], [[0, 1], [1, 2]]),
            {"thickness": 1e-3},
        ),
        lambda: (abdsim.AffineBodyConstitution("ARAP"), abdsim.geometry.sphere(0.1), {}),
    ],
    ids=["thin-shell", "thin-rod", "bent-rod", "sphere"],
)
def test_mass_matrix_is_spd(make):
    constitution, sc, kw = make()
    constitution.apply_to(sc, kappa=1e8, mass_density=RHO, **kw)
    M = abdsim.mass_matrix(sc)
    assert M.shape == (12, 12)
    np.testing.assert_allclose(M, M.T, rtol=0, atol=0)
    np.linalg.cholesky(M)  # raises LinAlgError unless SPD
    # structure of ABD_NOTES §3
    m, mx, s = sc.meta["abd_mass"], sc.meta["abd_mass_x_bar"], sc.meta["abd_mass_x_bar_x_bar"]
    np.testing.assert_array_equal(M[:3, :3], m * np.eye(3))
    for i in range(3):
        np.testing.assert_array_equal(M[i, 3 + 3 * i : 6 + 3 * i], mx)
        np.testing.assert_array_equal(M[3 + 3 * i : 6 + 3 * i, 3 + 3 * i : 6 + 3 * i], s)


def test_kinetic_energy_from_mass_matrix_matches_rigid_body():
    """½ q̇ᵀMq̇ of a rigid motion equals ½ m|v_c|² + ½ ωᵀ I_c ω (independent check of M)."""
    mesh = trimesh.creation.box(extents=(0.2, 0.4, 0.9))
    mesh.apply_translation([0.3, 0.0, -0.1])
    sc = solid(mesh)
    rb = abdsim.to_rigid_body(sc)
    omega = np.array([0.3, -1.2, 2.0])
    v_p = np.array([0.5, 0.1, -0.4])
    w = np.array([[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]])
    a_dot = w  # A = I at rest
    qdot = np.concatenate([v_p, a_dot[0], a_dot[1], a_dot[2]])
    ke = 0.5 * qdot @ abdsim.mass_matrix(sc) @ qdot
    v_c = v_p + np.cross(omega, rb.mass_center)
    expected = 0.5 * rb.mass * v_c @ v_c + 0.5 * omega @ rb.inertia @ omega
    assert ke == pytest.approx(expected, rel=1e-12)
