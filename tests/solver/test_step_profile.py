"""StepDiagnostics.profile: where a coupled step's time went and what cut its line searches,
checked against what the step itself reports (its accepted step lengths)."""

from __future__ import annotations

import math

import numpy as np

import abdsim

TIMERS = ("assembly", "linear_solve", "ccd", "line_search", "contact_update", "broad_phase")


def tilted_box_drop() -> abdsim.World:
    """One 10 cm box, tilted, released 2 cm above the ground with friction: one island."""
    sc = abdsim.geometry.box((0.1, 0.08, 0.06))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8, mass_density=1e3)
    c, s = math.cos(0.3), math.sin(0.3)
    T = np.eye(4)
    T[:3, :3] = [[1, 0, 0], [0, c, -s], [0, s, c]]
    T[2, 3] = 0.07
    sc.transforms = T[None]
    scene = abdsim.Scene(dt=0.01, friction=0.5)
    scene.add_ground(0.0)
    scene.add(sc)
    return abdsim.World(scene)


def is_power_of_two(a: float) -> bool:
    return 0.0 < a < 1.0 and math.frexp(a)[0] == 0.5


def test_profile_accounts_for_every_cut_step():
    """A single island: an accepted step α < 1 is ccd_safety × (CCD bound) × 2^−k, or 2^−k
    when only Armijo cut it. So the halvings are at least Σ k over the exact powers of two,
    and every other α < 1 was cut by the CCD bound."""
    world = tilted_box_drop()
    halvings = cuts = searches = 0
    powers = others = 0
    for _ in range(40):
        d = world.step()
        p = d.profile
        assert set(p) == {*TIMERS, "ccd_cuts", "armijo_halvings", "symbolic_analyses"}
        assert all(p[k] >= 0.0 for k in TIMERS)
        sections = sum(p[k] for k in TIMERS if k != "broad_phase")
        assert sections <= d.wall_time
        halvings += p["armijo_halvings"]
        cuts += p["ccd_cuts"]
        searches += len(d.line_search_alphas)
        for a in d.line_search_alphas:
            if is_power_of_two(a):
                powers += -math.frexp(a)[1] + 1
            elif 0.0 < a < 1.0:
                others += 1
    assert searches > 40  # it landed: coupled iterations with contact
    assert others > 0 and powers > 0  # both kinds of cut happened
    assert halvings >= powers
    assert others <= cuts <= searches
