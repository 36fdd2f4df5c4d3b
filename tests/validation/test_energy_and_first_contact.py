"""``abdsim validate`` catches contact that adds energy, finds short contacts from every step,
and states its accuracy tolerances for the step it runs at (issue "Physics at the defaults")."""

from __future__ import annotations

import numpy as np
import pytest

from abdsim.validation import validate
from abdsim.validation.compare import energy_gain_check
from abdsim.validation.scenes import SCENE_DIR
from abdsim.validation.tolerances import Tolerances
from abdsim.validation.trajectory import Trajectory


def _trajectory(energy, stored=None, extra=None) -> Trajectory:
    n = len(energy)
    data = {"stored_energy": np.asarray(stored if stored is not None else np.zeros(n))}
    data.update(extra or {})
    return Trajectory(
        "abdsim",
        ["b"],
        time=0.01 * np.arange(n),
        com=np.zeros((n, 1, 3)),
        rotation=np.tile(np.eye(3), (n, 1, 1, 1)),
        linear_momentum=np.zeros((n, 1, 3)),
        angular_momentum=np.zeros((n, 1, 3)),
        energy=np.asarray(energy, float),
        contact_distance=np.full(n, np.nan),
        extra=data,
    )


def test_energy_gain_check_fails_on_a_gain_and_passes_a_loss():
    tol = Tolerances()
    # a bounce that comes back 1 % higher (the old barrier stiffening did 20-40 %)
    check, summary = energy_gain_check(_trajectory([10.0, 10.0, 6.0, 10.1, 10.1]), tol)
    assert not check.passed and summary["energy_gain"] == pytest.approx(4.1 / 10.1)
    # kinetic energy moved into the barrier and back is no gain; dissipation passes
    stored = [0.0, 4.0, 0.0, 0.0]
    check, _ = energy_gain_check(_trajectory([10.0, 6.0, 9.5, 9.0], stored), tol)
    assert check.passed


def test_validate_fails_when_the_energy_gain_tolerance_is_zero(tmp_path):
    """The check is live in a real run: the resting scene's energy moves by round-off
    (~1e-17 of it) at rest, so a tolerance of exactly zero must fail it, or show it never
    rises, and the default 1e-3 passes."""
    scene = SCENE_DIR / "resting_bodies.xml"
    strict = validate(
        scene,
        duration=0.3,
        dt=1e-2,
        out=tmp_path / "s",
        progress=False,
        mcap=False,
        tolerances=Tolerances(energy_gain=-1e-15),
    )
    names = [c.name for c in strict.failed]
    assert "energy gain between samples (rel)" in names
    loose = validate(scene, duration=0.3, dt=1e-2, out=tmp_path / "l", progress=False, mcap=False)
    energy = [c for c in loose.checks if c.name == "energy gain between samples (rel)"]
    assert energy and energy[0].passed
    assert loose.metrics["energy"]["energy_gain"] < 1e-3


def test_first_contact_comes_from_every_step_not_samples():
    """A contact shorter than the sampling interval is found: with every step recorded the
    trajectory's first-contact time is that step's time, whatever the samples say."""
    tr = _trajectory([1.0, 1.0, 1.0], extra={"first_contact_time": 0.013})
    assert tr.first_contact_time(1e-3) == 0.013
    assert _trajectory([1.0, 1.0]).first_contact_time() == float("inf")


def test_free_bodies_scene_validates_with_its_short_contacts(tmp_path):
    res = validate(
        SCENE_DIR / "free_bodies.xml",
        duration=1.0,
        dt=1e-3,
        out=tmp_path,
        progress=False,
        mcap=False,
    )
    assert res.passed, [(c.name, c.body, c.value, c.limit) for c in res.failed]
    c = res.metrics["contact"]
    assert np.isfinite(c["first_contact_abdsim"]) and np.isfinite(c["first_contact_mujoco"])


def test_accuracy_tolerances_follow_the_methods_order():
    t = Tolerances()
    assert t.at_step(1e-3) == t and t.at_step(5e-4) == t
    coarse = t.at_step(1e-2, "bdf2")
    assert coarse.free_flight_position == pytest.approx(100 * t.free_flight_position)
    assert t.at_step(1e-2, "bdf1").free_flight_position == pytest.approx(
        10 * t.free_flight_position
    )
    # contact, energy gain and inertia are not integration errors: unchanged
    for name in ("min_contact_distance", "energy_gain", "inertia_rel", "first_contact_time"):
        assert getattr(coarse, name) == getattr(t, name)


def test_stored_energy_is_the_shape_energy_and_refuses_a_world_without_energies():
    import abdsim
    from abdsim.validation.abdsim_runner import stored_energy

    box = abdsim.geometry.box((0.1, 0.2, 0.3))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(box, kappa=1e8, mass_density=1e3)
    box.transforms[:, :3, :3] = np.diag([1.01, 1.0, 1.0])  # stretched 1 %: Ψ > 0
    scene = abdsim.Scene(dt=0.01, gravity=(0, 0, 0), contact=False)
    scene.add(box)
    world = abdsim.World(scene)
    world.step()
    A = world.q[0, 3:].reshape(3, 3)
    psi = np.sum((A @ A.T - np.eye(3)) ** 2)
    volume = 0.1 * 0.2 * 0.3
    assert stored_energy(world) == pytest.approx(1e8 * volume * psi, rel=1e-9)

    scene.settings.energies = False
    with pytest.raises(ValueError, match="SceneSettings.energies is off"):
        stored_energy(abdsim.World(scene))
