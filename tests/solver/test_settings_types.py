"""Settings are type-checked: flags are bools, numbers real numbers, counts integers."""

from __future__ import annotations

import numpy as np
import pytest

import abdsim
from abdsim.sim.settings import _KINDS, SceneSettings


def test_every_setting_has_a_declared_type():
    assert set(_KINDS) == set(SceneSettings.field_names())


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"dt": True}, "dt must be a real number"),
        ({"dt": "0.01"}, "dt must be a real number"),
        ({"contact": "False"}, "contact must be a bool"),
        ({"contact": 0}, "contact must be a bool"),
        ({"project_psd": 1}, "project_psd must be a bool"),
        ({"newton_max_iterations": 20.5}, "newton_max_iterations must be an integer"),
        ({"num_threads": True}, "num_threads must be an integer"),
        ({"friction": None}, "friction must be a real number"),
        ({"integrator": 2}, "integrator must be a string"),
    ],
)
def test_wrong_types_are_refused(kwargs, match):
    with pytest.raises(TypeError, match=match):
        abdsim.Scene(**kwargs)


def test_wrong_type_set_after_construction_is_refused_by_world():
    scene = abdsim.Scene()
    sc = abdsim.geometry.box(0.1)
    abdsim.AffineBodyConstitution().apply_to(sc, 1e8)
    scene.add(sc)
    scene.settings.dt = True
    with pytest.raises(TypeError, match="dt must be a real number"):
        abdsim.World(scene)


def test_numpy_scalars_are_accepted_and_used():
    scene = abdsim.Scene(
        dt=np.float32(0.01),
        newton_max_iterations=np.int64(50),
        contact=np.bool_(False),
        friction=np.float64(0.3),
    )
    sc = abdsim.geometry.box(0.1)
    abdsim.AffineBodyConstitution().apply_to(sc, 1e8)
    scene.add(sc)
    world = abdsim.World(scene)
    world.step(10)
    # free fall from rest: z = -g t² / 2 with t = 10 h, h the float32 time step
    h = float(np.float32(0.01))
    assert world.time == pytest.approx(10 * h, rel=1e-12)
    assert world.q[0, 2] == pytest.approx(-0.5 * 9.81 * (10 * h) ** 2, rel=1e-6)
    assert world.contact is None
