"""No intersection, ever: scenes run through the public Scene/World API with contact, checked
at every step by an independent test (coal's triangle-level collision and distance between
every pair of bodies, built here from world-space meshes; vertices against the ground)."""

import numpy as np
import pytest
import trimesh

import abdsim

DT = 0.01


def l_prism(a: float, b: float, height: float) -> trimesh.Trimesh:
    """An L-shaped prism: the L is an a x a square with an (a - b) x (a - b) corner cut out."""
    poly = np.array([[0, 0], [a, 0], [a, b], [b, b], [b, a], [0, a]], float) - a / 3
    n = len(poly)
    V = np.vstack([np.c_[poly, np.zeros(n)], np.c_[poly, np.full(n, height)]])
    V[:, 2] -= height / 2
    caps = [(3, 4, 5), (3, 5, 0), (3, 0, 1), (3, 1, 2)]  # a fan from the reflex corner
    F = [(i, k, j) for i, j, k in caps] + [(n + i, n + j, n + k) for i, j, k in caps]
    for i in range(n):
        j = (i + 1) % n
        F += [(i, j, n + j), (i, n + j, n + i)]
    mesh = trimesh.Trimesh(V, np.array(F), process=False)
    assert mesh.is_watertight and mesh.volume > 0
    return mesh


def random_rotations(rng, n):
    return np.array(
        [trimesh.transformations.random_rotation_matrix(rng.random(3))[:3, :3] for _ in range(n)]
    )


def test_random_pile_of_non_convex_bodies_never_intersects(wc):
    """24 bodies (tori, annuli, L-prisms, boxes; non-convex ones interlock) dropped at random
    orientations onto the ground and onto each other, dt = 0.01: at every step coal finds no
    intersecting pair, every pairwise distance and every vertex height stays > 0."""
    rng = np.random.default_rng(7)
    meshes = [
        trimesh.creation.torus(0.04, 0.012, major_sections=16, minor_sections=8),
        trimesh.creation.annulus(r_min=0.02, r_max=0.04, height=0.02, sections=16),
        l_prism(0.08, 0.03, 0.03),
        trimesh.creation.box(extents=(0.07, 0.05, 0.04)),
    ]
    per_kind = 6
    scene = abdsim.Scene(dt=DT, friction=0.4)
    scene.add_ground(0.0)
    slots = rng.permutation(len(meshes) * per_kind)
    for kind, mesh in enumerate(meshes):
        sc = wc.solid(mesh, n=per_kind)
        idx = slots[kind * per_kind : (kind + 1) * per_kind]
        # 2 x 2 columns of layers 12 cm apart (bodies are at most 10.4 cm across): each
        # layer lands on the one below
        pos = np.stack(
            [0.11 * (idx % 2), 0.11 * ((idx // 2) % 2), 0.08 + 0.12 * (idx // 4)], axis=1
        )
        pos[:, :2] += rng.uniform(-0.003, 0.003, size=(per_kind, 2))
        wc.place(sc, pos, random_rotations(rng, per_kind))
        V = np.zeros((per_kind, 4, 4))
        V[:, :3, 3] = rng.normal(scale=0.3, size=(per_kind, 3))
        sc.instances["velocity"] = V
        scene.add(sc)
    world = abdsim.World(scene)
    hits, d_min, low = wc.coal_check(world)
    assert hits == 0 and d_min > 0 and low > 0
    worst_d, worst_low, pairs = np.inf, np.inf, 0
    for _ in range(110):
        diag = world.step()
        hits, d_min, low = wc.coal_check(world)
        assert hits == 0, f"step {diag.step}: {hits} intersecting pairs"
        worst_d, worst_low = min(worst_d, d_min), min(worst_low, low)
        pairs = max(pairs, diag.contact_pairs["point_triangle"] + diag.contact_pairs["edge_edge"])
    assert worst_d > 0 and worst_low > 0
    assert pairs > 0  # bodies did land on bodies
    # everything has come down onto the pile (the top layer started at 0.68 m)
    assert world.transforms()[:, 2, 3].max() < 0.3
    print(f"min distance {worst_d:.2e} m, lowest vertex {worst_low:.2e} m, pairs {pairs}")


@pytest.mark.parametrize("speed", [10.0, 50.0])
def test_fast_small_body_does_not_tunnel_through_thin_obstacles(wc, speed):
    """A 2 cm box at 10 or 50 m/s (10-50 cm per step, 5-25 times its size) hits a fixed thin
    shell (0.5 mm thickness radius) and a fixed 2 mm thin box: it ends on the near side, and
    no step ever has an intersection (coal, shell surface inflated by nothing: the gap it
    measures includes the thickness)."""
    for obstacle in ("shell", "thin_box"):
        scene = abdsim.Scene(dt=DT, gravity=(0, 0, 0))
        if obstacle == "shell":
            plate = trimesh.creation.box(extents=(0.6, 0.6, 0.1))
            top = plate.vertices[:, 2] > 0  # the top face as an open triangle mesh
            faces = [f for f in plate.faces if top[f].all()]
            used = np.unique(faces)
            remap = -np.ones(len(plate.vertices), int)
            remap[used] = np.arange(len(used))
            sheet = abdsim.geometry.triangle_mesh(
                plate.vertices[used] * [1, 1, 0], remap[np.array(faces)]
            )
            abdsim.AffineBodyShell().apply_to(sheet, kappa=1e8, thickness=5e-4)
        else:
            sheet = wc.box((0.6, 0.6, 0.002))
        sheet.instances["is_fixed"] = np.array([1])
        scene.add(sheet)
        bullet = wc.box((0.02, 0.02, 0.02))
        wc.place(bullet, [[0.01, -0.02, 0.3]], random_rotations(np.random.default_rng(1), 1))
        V = np.zeros((1, 4, 4))
        V[0, :3, 3] = [0.0, 0.0, -speed]
        bullet.instances["velocity"] = V
        scene.add(bullet)
        world = abdsim.World(scene)
        for _ in range(30):
            world.step()
            hits, d_min, _ = wc.coal_check(world)
            assert hits == 0 and d_min > 0, obstacle
        z = world.vertices(scene.handles[1])[0, :, 2]
        v_z = world.velocities()[1, 2, 3]
        assert z.min() > 0, obstacle  # still above the obstacle's (mid-)surface
        assert v_z > -0.1 * speed  # stopped (or bounced), not flying on
        assert z.min() < 0.01 or v_z > 0, obstacle  # it did reach the obstacle
