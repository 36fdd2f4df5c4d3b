"""Each bad input of the foundation raises a ValueError that names the problem."""

import numpy as np
import pytest
import trimesh

import abdsim

CUBE = trimesh.creation.box()


def surface(vertices, faces):
    return abdsim.geometry.triangle_mesh(vertices, faces)


def test_open_mesh_as_solid():
    sc = surface(CUBE.vertices, CUBE.faces[:-1])
    with pytest.raises(ValueError, match="open"):
        abdsim.AffineBodyConstitution().apply_to(sc, kappa=1e8)
    # ... but fine as a shell
    abdsim.AffineBodyShell().apply_to(sc, kappa=1e8)


def test_non_manifold_mesh():
    faces = np.vstack([CUBE.faces, CUBE.faces[:2]])
    with pytest.raises(ValueError, match="non-manifold"):
        abdsim.AffineBodyConstitution().apply_to(surface(CUBE.vertices, faces), kappa=1e8)


def test_inconsistent_orientation():
    faces = CUBE.faces.copy()
    faces[0] = faces[0][::-1]
    with pytest.raises(ValueError, match="inconsistently oriented"):
        abdsim.AffineBodyConstitution().apply_to(surface(CUBE.vertices, faces), kappa=1e8)


def test_inward_oriented_surface_has_negative_volume():
    with pytest.raises(ValueError, match="inward"):
        abdsim.AffineBodyConstitution().apply_to(
            surface(CUBE.vertices, CUBE.faces[:, ::-1]), kappa=1e8
        )


def test_degenerate_triangle():
    v = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], dtype=float)
    with pytest.raises(ValueError, match="zero area"):
        abdsim.AffineBodyShell().apply_to(surface(v, [[0, 1, 2]]), kappa=1e8)


def test_zero_length_rod_segment():
    sc = abdsim.geometry.edge_mesh([[0, 0, 0], [1, 0, 0], [1, 0, 0]], [[0, 1], [1, 2]])
    with pytest.raises(ValueError, match="zero length"):
        abdsim.AffineBodyRod().apply_to(sc, kappa=1e8)


@pytest.mark.parametrize("kappa", [0.0, -1e8, np.nan, np.inf])
def test_non_positive_kappa(kappa):
    with pytest.raises(ValueError, match="kappa"):
        abdsim.AffineBodyConstitution().apply_to(abdsim.geometry.box(), kappa=kappa)


@pytest.mark.parametrize("rho", [0.0, -5.0, np.nan])
def test_non_positive_density(rho):
    with pytest.raises(ValueError, match="mass_density"):
        abdsim.AffineBodyConstitution().apply_to(abdsim.geometry.box(), 1e8, mass_density=rho)


@pytest.mark.parametrize("r", [0.0, -0.01, np.inf])
def test_non_positive_thickness(r):
    with pytest.raises(ValueError, match="thickness"):
        abdsim.AffineBodyShell().apply_to(abdsim.geometry.box(), 1e8, thickness=r)
    with pytest.raises(ValueError, match="thickness"):
        abdsim.AffineBodyRod().apply_to(
            abdsim.geometry.edge_mesh([[0, 0, 0], [1, 0, 0]], [[0, 1]]), 1e8, thickness=r
        )


def test_wrong_mesh_kind_for_constitution():
    rod = abdsim.geometry.edge_mesh([[0, 0, 0], [1, 0, 0]], [[0, 1]])
    with pytest.raises(ValueError, match="AffineBodyRod"):
        abdsim.AffineBodyConstitution().apply_to(rod, kappa=1e8)
    with pytest.raises(ValueError, match="triangle mesh"):
        abdsim.AffineBodyShell().apply_to(rod, kappa=1e8)


def test_kappa_outside_recommended_range_warns():
    with pytest.warns(UserWarning, match="recommended range"):
        abdsim.AffineBodyConstitution().apply_to(abdsim.geometry.box(), kappa=1e5)


def test_mass_properties_require_constitution():
    with pytest.raises(ValueError, match="apply a constitution"):
        abdsim.to_rigid_body(abdsim.geometry.box())
