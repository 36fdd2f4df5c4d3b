"""The _core mass functions check every index and size they are given (no read out of range).

Each of these inputs crashed the interpreter (or returned a garbage volume) before.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import abdsim
from abdsim._native import _core

TET_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
TET = np.array([[0, 1, 2, 3]], dtype=np.int32)
TRI = np.array([[0, 1, 2]], dtype=np.int32)
EDGE = np.array([[0, 1]], dtype=np.int32)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: _core.tet_mesh_mass(TET_V[:1], TET, 1e3), "tetrahedron 0 has vertex index 1"),
        (lambda: _core.tet_mesh_mass(TET_V, TET + 100, 1e3), "out of range"),
        (lambda: _core.tet_mesh_mass(TET_V, -TET - 1, 1e3), "out of range"),
        (lambda: _core.closed_surface_mass(TET_V, TRI + 4, 1e3), "triangle 0"),
        (lambda: _core.shell_mass(TET_V, TRI + 2, np.ones(4), 1e3), "triangle 0"),
        (lambda: _core.shell_mass(TET_V, TRI, np.ones(2), 1e3), "thickness has 2 values"),
        (lambda: _core.rod_mass(TET_V, EDGE + 9, np.ones(4), 1e3), "edge 0"),
        (lambda: _core.rod_mass(TET_V, EDGE, np.ones(1), 1e3), "thickness has 1 values"),
    ],
)
def test_out_of_range_indices_and_short_arrays_raise(call, match):
    with pytest.raises((ValueError, IndexError), match=match):
        call()


@pytest.mark.parametrize("bad", [np.nan, np.inf, -1.0, 0.0])
def test_bad_thickness_values_raise(bad):
    r = np.array([0.01, bad, 0.01, 0.01])
    with pytest.raises(ValueError, match="thickness of vertex 1"):
        _core.shell_mass(TET_V, TRI, r, 1e3)
    with pytest.raises(ValueError, match="thickness of vertex 1"):
        _core.rod_mass(TET_V, EDGE, r, 1e3)


def test_non_finite_vertices_and_dyadic_mass_raise():
    v = TET_V.copy()
    v[2, 1] = np.nan
    with pytest.raises(ValueError, match="vertex 2"):
        _core.tet_mesh_mass(v, TET, 1e3)
    with pytest.raises(ValueError, match="finite"):
        _core.mass_matrix(1.0, np.array([np.nan, 0, 0]), np.eye(3))
    with pytest.raises(ValueError, match="finite"):
        _core.to_rigid_body(1.0, np.zeros(3), np.full((3, 3), np.inf))
    with pytest.raises(ValueError, match="finite"):
        _core.from_rigid_body(1.0, np.zeros(3), np.full((3, 3), np.nan))


def test_valid_input_still_matches_the_closed_form():
    # Unit right tetrahedron: volume 1/6, centroid (1/4, 1/4, 1/4).
    m, mx, _ = _core.tet_mesh_mass(TET_V, TET, 6.0)
    assert m == pytest.approx(1.0, rel=1e-14)
    np.testing.assert_allclose(mx, [0.25, 0.25, 0.25], rtol=1e-14)


def test_vertices_resized_after_construction_are_refused_by_apply_to():
    mesh = trimesh.creation.box()
    tets_v = np.vstack([mesh.vertices, [[0.0, 0.0, 0.0]]])
    tets = np.array([[f[0], f[2], f[1], 8] for f in mesh.faces], dtype=np.int32)
    sc = abdsim.geometry.tet_mesh(tets_v, tets)
    sc.vertices.resize(1)
    with pytest.raises(ValueError, match="refers to vertex"):
        abdsim.AffineBodyConstitution().apply_to(sc, 1e8)


def test_thickness_resized_or_corrupted_after_apply_to_is_refused_by_world():
    v = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    sc = abdsim.geometry.triangle_mesh(v, np.array([[0, 1, 2], [0, 2, 3]]))
    abdsim.AffineBodyShell().apply_to(sc, 1e8, thickness=0.01)
    sc.vertices["thickness"][2] = np.inf
    scene = abdsim.Scene()
    scene.add(sc)
    with pytest.raises(ValueError, match="thickness of vertex 2 must be positive and finite"):
        abdsim.World(scene)
