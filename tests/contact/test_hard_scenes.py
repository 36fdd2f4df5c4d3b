"""Hard scenes at default settings (issue "Never crash, never silently wrong", item 5): a heavy
ball on a free shell plate, rods landing on a shell, a 30-box pile at dt = 0.05. They must run
without SolverError and stay intersection-free, checked independently with coal. (These
configurations also ran before substeps existed: the reported failures were at settings not
recorded in the issue; the tests hold the behaviour, they do not reproduce the failure.)"""

from __future__ import annotations

import numpy as np

import abdsim


def shell_plate(size: float = 1.0, n: int = 8, thickness: float = 0.005, density=1e3):
    """A flat n x n triangulated square shell of half-thickness `thickness` at z = 0."""
    xs = np.linspace(-size / 2, size / 2, n + 1)
    X, Y = np.meshgrid(xs, xs)
    V = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)
    F = []
    for i in range(n):
        for j in range(n):
            a = i * (n + 1) + j
            F += [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
    sc = abdsim.geometry.triangle_mesh(V, np.array(F))
    abdsim.AffineBodyShell().apply_to(sc, kappa=1e8, thickness=thickness, mass_density=density)
    return sc


def checked_steps(wc, world, steps):
    """Steps `world`, checking every state with coal (no intersection, positive gaps);
    yields each step's diagnostics."""
    for _ in range(steps):
        d = world.step()
        hits, d_min, low = wc.coal_check(world)
        assert hits == 0 and d_min > 0 and low > 0
        yield d


def run_checked(wc, world, steps):
    for _ in checked_steps(wc, world, steps):
        pass


def test_heavy_sphere_on_a_free_shell_plate(wc):
    """Mass ratio 1,000 (a 10 t ball on a 10 kg plate resting on the ground), dt = 0.01."""
    scene = abdsim.Scene(dt=0.01)
    scene.add_ground(-0.01)
    plate = shell_plate()
    scene.add(plate)
    ball = abdsim.geometry.sphere(0.1)
    plate_mass = float(plate.meta["abd_mass"])
    abdsim.AffineBodyConstitution().apply_to(
        ball, kappa=1e8, mass_density=1000 * plate_mass / (4 / 3 * np.pi * 0.1**3)
    )
    ball.transforms[:, 2, 3] = 0.2
    scene.add(ball)
    world = abdsim.World(scene)
    run_checked(wc, world, 40)
    assert abs(world.velocities()[1, 2, 3]) < 0.05  # it landed and stopped on the plate


def test_rods_landing_on_a_shell(wc):
    scene = abdsim.Scene(dt=0.01)
    plate = shell_plate()
    plate.instances["is_fixed"] = np.array([1])
    scene.add(plate)
    rod = abdsim.geometry.edge_mesh(np.array([[0, 0, 0], [0.3, 0, 0]], float), np.array([[0, 1]]))
    rod.instances.resize(3)
    rod.transforms[:, :3, 3] = [[-0.15, -0.2, 0.3], [-0.15, 0.0, 0.5], [-0.15, 0.2, 0.7]]
    abdsim.AffineBodyRod().apply_to(rod, kappa=1e8, thickness=0.005)
    scene.add(rod)
    world = abdsim.World(scene)
    for _ in range(80):
        world.step()
    z = world.transforms()[1:, 2, 3]
    # resting on the plate: rod and shell radii (5 mm each) plus a gap within d̂ = 1 mm
    assert np.all((z > 0.01) & (z < 0.012))


def test_a_pile_of_thirty_boxes_at_dt_0_05(wc):
    scene = abdsim.Scene(dt=0.05)
    scene.add_ground()
    boxes = abdsim.geometry.box((0.1, 0.1, 0.1))
    boxes.instances.resize(30)
    boxes.transforms[:, :3, 3] = [
        [0.12 * (i % 5), 0.12 * ((i // 5) % 3), 0.06 + 0.12 * (i // 15)] for i in range(30)
    ]
    abdsim.AffineBodyConstitution().apply_to(boxes, kappa=1e8)
    scene.add(boxes)
    world = abdsim.World(scene)
    run_checked(wc, world, 20)


def swarm(speed: float, n: int = 12, seed: int = 0) -> abdsim.World:
    """n 10 cm boxes on a ring of radius 0.6 m at three heights, all aimed at one point above
    the ground with a random jitter of about 6° (issue item 5's swarm), default settings."""
    rng = np.random.default_rng(seed)
    scene = abdsim.Scene()
    scene.add_ground(0.0)
    boxes = abdsim.geometry.box(0.1)
    boxes.instances.resize(n)
    angle = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    p = np.stack([0.6 * np.cos(angle), 0.6 * np.sin(angle), 0.3 + 0.15 * (np.arange(n) % 3)], 1)
    aim = np.array([0.0, 0.0, 0.3]) - p
    aim = aim / np.linalg.norm(aim, axis=1)[:, None] + 0.1 * rng.standard_normal((n, 3))
    v = np.zeros((n, 4, 4))
    v[:, :3, 3] = speed * aim / np.linalg.norm(aim, axis=1)[:, None]
    boxes.transforms[:, :3, 3] = p
    boxes.instances["velocity"] = v
    abdsim.AffineBodyConstitution().apply_to(boxes, kappa=1e8)
    scene.add(boxes)
    return abdsim.World(scene)


def swarm_speeds():
    """10 and 80 m/s always; 20 and 40 m/s (the slowest: one step needs 256 pieces, ~12 s)
    with ABDSIM_HEAVY_TESTS=1."""
    import os

    import pytest

    heavy = pytest.mark.skipif(
        os.environ.get("ABDSIM_HEAVY_TESTS") != "1", reason="set ABDSIM_HEAVY_TESTS=1"
    )
    return [10.0, 80.0, pytest.param(20.0, marks=heavy), pytest.param(40.0, marks=heavy)]


def pytest_generate_tests(metafunc):
    if "swarm_speed" in metafunc.fixturenames:
        metafunc.parametrize("swarm_speed", swarm_speeds())


def test_a_swarm_colliding_at_10_to_80_m_s(wc, swarm_speed):
    """Twelve boxes meeting head-on at 10–80 m/s at dt = 0.01 (a step moves them up to 8 times
    their size): no SolverError, no intersection at any step (coal), and, while nothing has
    reached the ground, the horizontal momentum of the swarm is what it was (contact forces
    come in equal and opposite pairs, in every substep)."""
    world = swarm(swarm_speed)
    momentum0 = world.velocities()[:, :2, 3].sum(axis=0)
    substeps = []
    grounded = False  # a box has come near the ground (which takes momentum) at some step
    for d in checked_steps(wc, world, 12):
        substeps.append(d.substeps)
        grounded = grounded or d.contact_pairs["point_ground"] > 0
        if not grounded:  # no box has reached the ground yet
            drift = world.velocities()[:, :2, 3].sum(axis=0) - momentum0
            assert np.abs(drift).max() < 1e-12 * swarm_speed * 12
    assert max(substeps) > 1  # the collisions needed pieces: this is the hard case
