"""Bad input raises clear exceptions; a failed step leaves the state as it was."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim


@pytest.mark.parametrize("dt", [0.0, -0.01, np.nan, np.inf])
def test_bad_dt(dt):
    with pytest.raises(ValueError, match="dt must be a positive finite"):
        abdsim.Scene(dt=dt)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"gravity": (0, np.nan, 0)}, ValueError, "gravity"),
        ({"gravity": (0, 0)}, ValueError, "gravity"),
        ({"integrator": "rk4"}, ValueError, "integrator"),
        ({"linear_solver": "cholmod"}, ValueError, "linear_solver"),
        ({"newton_tol_affine": 0.0}, ValueError, "newton_tol_affine"),
        ({"newton_max_iterations": 0}, ValueError, "newton_max_iterations"),
        ({"ccd_safety": 1.5}, ValueError, "ccd_safety"),
        ({"d_hat_typo": 1e-3}, TypeError, "unknown scene setting"),
    ],
)
def test_bad_settings(kwargs, error, match):
    with pytest.raises(error, match=match):
        abdsim.Scene(**kwargs)


def test_geometry_without_constitution():
    scene = abdsim.Scene()
    with pytest.raises(ValueError, match="no constitution"):
        scene.add(abdsim.geometry.box(1.0))
    with pytest.raises(TypeError, match="SimplicialComplex"):
        scene.add("box")


def test_same_geometry_twice(tools):
    scene = abdsim.Scene()
    sc = tools.make_box()
    scene.add(sc)
    with pytest.raises(ValueError, match="already added"):
        scene.add(sc)


def test_empty_scene():
    with pytest.raises(ValueError, match="no bodies"):
        abdsim.World(abdsim.Scene())


@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_non_finite_state(tools, value):
    sc = tools.make_box(2)
    T = np.tile(np.eye(4), (2, 1, 1))
    T[1, 0, 3] = value
    sc.instances["transform"] = T  # bypasses the SimplicialComplex setter's check
    with pytest.raises(ValueError, match="NaN or infinite"):
        tools.world_of(sc)
    sc = tools.make_box(2)
    V = np.zeros((2, 4, 4))
    V[0, 1, 1] = value
    sc.instances["velocity"] = V
    with pytest.raises(ValueError, match="velocity"):
        tools.world_of(sc)


def test_not_an_affine_transform(tools):
    sc = tools.make_box()
    T = np.eye(4)
    T[3, 0] = 1.0
    sc.instances["transform"] = T[None]
    with pytest.raises(ValueError, match=r"last row"):
        tools.world_of(sc)


def test_singular_mass_matrix(tools):
    sc = tools.make_box()
    sc.meta["abd_mass_x_bar_x_bar"] = np.diag([1.0, 1.0, 0.0])  # a flat body with no thickness
    with pytest.raises(ValueError, match="body 0 .*singular mass matrix"):
        tools.world_of(sc)


def test_bad_kappa_and_instance_count(tools):
    sc = tools.make_box(2)
    sc.instances["kappa"] = np.array([1e8, -1.0])
    with pytest.raises(ValueError, match="kappa"):
        tools.world_of(sc)
    sc = tools.make_box(2)
    scene = abdsim.Scene()
    scene.add(sc)
    sc.instances.resize(3)
    with pytest.raises(ValueError, match="instances"):
        abdsim.World(scene)


def test_newton_failure_raises_and_keeps_state(tools):
    sc = tools.make_box()
    T = np.eye(4)
    T[:3, :3] = [[1.0, 0.3, 0.0], [0.0, 1.0, 0.0], [0.0, 0.1, 0.9]]
    sc.transforms = T[None]
    world = tools.world_of(sc, newton_max_iterations=1)
    before = world.transforms()
    with pytest.raises(abdsim.SolverError, match=r"Newton failed for body 0 .*1 iterations"):
        world.step()
    assert isinstance(abdsim.SolverError("x"), RuntimeError)
    assert np.array_equal(world.transforms(), before)
    assert world.step_count == 0 and world.time == 0.0


def test_bad_calls_on_a_world(tools):
    sc = tools.make_box(2)
    sc.instances["is_fixed"] = np.array([0, 1])
    world = tools.world_of(sc)
    bad = np.eye(4)
    bad[0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN or infinite"):
        world.set_kinematic_target(0, bad)
    with pytest.raises(IndexError, match="out of range"):
        world.set_kinematic_target(5, np.eye(4))
    with pytest.raises(ValueError, match="fixed"):
        world.set_kinematic_target(1, np.eye(4))
    with pytest.raises(TypeError, match="callable"):
        world.set_kinematic_schedule(0, np.eye(4))
    with pytest.raises(ValueError, match="positive integer"):
        world.step(0)
    with pytest.raises(ValueError, match="NaN or infinite"):
        world.set_state(velocities=np.full((2, 4, 4), np.inf))
    with pytest.raises(ValueError, match=r"shape \(2, 4, 4\)"):
        world.set_state(transforms=np.eye(4))
