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


def run_checked(wc, world, steps):
    for _ in range(steps):
        world.step()
        hits, d_min, low = wc.coal_check(world)
        assert hits == 0 and d_min > 0 and low > 0


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
