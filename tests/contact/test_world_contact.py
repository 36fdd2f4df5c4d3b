"""Contact through the public Scene/World API, against closed forms and independent checks:
resting contact (gaps, drift), Coulomb friction on an incline, the contact table, self
collision, shells and rods through their thickness, the initial-configuration check,
kinematic bodies pushing, BDF2, determinism."""

import numpy as np
import pytest
import trimesh

import abdsim

DT = 0.01
G = 9.81
D_HAT = 1e-3


def vertex_speed(world, handle):
    """Largest speed of any vertex of the handle's bodies (m/s)."""
    qd = world.q_dot[handle.start : handle.stop]
    A = qd[:, 3:].reshape(-1, 3, 3)
    v = np.einsum("kij,vj->kvi", A, handle.sc.positions) + qd[:, None, :3]
    return float(np.linalg.norm(v, axis=-1).max())


def rotation_y(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


# -- resting contact ------------------------------------------------------------------------
def test_box_on_the_ground_comes_to_rest_inside_the_barrier(wc):
    """Released 0.5 mm above the ground: the gap settles in (0, d̂] and the box is still
    (every vertex slower than 1e-6 m/s)."""
    scene = abdsim.Scene(dt=DT)
    scene.add_ground(0.0)
    sc = wc.box((0.2, 0.15, 0.1))
    wc.place(sc, [[0.0, 0.0, 0.0505]])
    h = scene.add(sc)
    world = abdsim.World(scene)
    speeds = []
    for _ in range(150):
        d = world.step()
        speeds.append(vertex_speed(world, h))
    gap = world.vertices(h)[0][:, 2].min()
    assert 0 < gap <= D_HAT
    assert d.min_contact_distance == pytest.approx(gap, rel=1e-9)
    assert d.contact_pairs["point_ground"] == 4 and d.contact_pairs["friction"] == 4
    assert max(speeds[-50:]) < 1e-6
    print(f"box: gap {gap:.3e} m, drift {max(speeds[-50:]):.1e} m/s")


def test_stack_of_five_boxes_comes_to_rest(wc):
    """Five boxes (10, 9, 8, 7, 6 cm) stacked 0.5 mm apart: every gap settles in (0, d̂],
    and over the last second every vertex moves slower than 1e-6 m/s."""
    scene = abdsim.Scene(dt=DT)
    scene.add_ground(0.0)
    handles, z = [], 0.0005
    for k in range(5):
        s = 0.1 - 0.01 * k
        sc = wc.box((s, s, s))
        wc.place(sc, [[0.0, 0.0, z + s / 2]])
        z += s + 0.0005
        handles.append(scene.add(sc))
    world = abdsim.World(scene)
    drift = []
    for _ in range(200):
        world.step()
        drift.append(max(vertex_speed(world, h) for h in handles))
    Z = [world.vertices(h)[0][:, 2] for h in handles]
    gaps = [Z[0].min()] + [Z[k].min() - Z[k - 1].max() for k in range(1, 5)]
    assert all(0 < g <= D_HAT for g in gaps), gaps
    assert max(drift[-100:]) < 1e-6
    hits, d_min, _ = wc.coal_check(world)
    assert hits == 0 and d_min > 0
    print(f"stack: gaps {np.round(np.array(gaps) * 1e3, 3)} mm, drift {max(drift[-100:]):.1e} m/s")


# -- friction ---------------------------------------------------------------------------------
def incline_world(wc, tan_theta, mu=0.5, integrator="bdf1", n=1, elements=0, table=()):
    """Boxes resting 0.5 mm above the ground, gravity tilted by θ about y (an incline)."""
    theta = np.arctan(tan_theta)
    gravity = G * np.array([np.sin(theta), 0.0, -np.cos(theta)])
    scene = abdsim.Scene(dt=DT, gravity=gravity, friction=mu, integrator=integrator)
    scene.add_ground(0.0)
    sc = wc.box((0.1, 0.1, 0.1), n=n)
    wc.place(sc, [[0.0, 0.3 * k, 0.0505] for k in range(n)])
    h = scene.add(sc, contact_element=elements)
    for a, b, mu_ab in table:
        scene.contact_table.set(a, b, friction=mu_ab)
    return abdsim.World(scene), h, theta


def sliding_acceleration(world, body=0, settle=30, steps=80):
    """Least-squares slope of the x velocity after `settle` steps."""
    world.step(settle)
    t, v = [], []
    for _ in range(steps):
        world.step()
        t.append(world.time)
        v.append(world.velocities()[body, 0, 3])
    return np.polyfit(t, v, 1)[0]


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_box_slides_down_an_incline_with_coulomb_acceleration(wc, integrator):
    """tan θ = 0.7 > μ = 0.5: a = g (sin θ − μ cos θ) within 2 % (lagged friction at the
    right potential scale for BDF1 and BDF2)."""
    world, _, theta = incline_world(wc, 0.7, integrator=integrator)
    a = sliding_acceleration(world)
    expected = G * (np.sin(theta) - 0.5 * np.cos(theta))
    assert a == pytest.approx(expected, rel=0.02)
    print(f"{integrator}: a = {a:.4f} m/s², closed form {expected:.4f} ({a / expected - 1:+.2%})")


def test_box_sticks_on_an_incline_below_the_friction_angle(wc):
    """tan θ = 0.3 < μ = 0.5: it only creeps (IPC's smoothed static friction), slower than
    ε_v = 1e-3 m/s, and keeps its contact."""
    world, h, _ = incline_world(wc, 0.3)
    world.step(30)
    x0 = world.transforms()[0, 0, 3]
    world.step(100)
    creep = (world.transforms()[0, 0, 3] - x0) / 1.0
    assert 0 <= creep < 1e-3
    assert abs(world.velocities()[0, 0, 3]) < 1e-3
    assert 0 < world.vertices(h)[0][:, 2].min() <= D_HAT
    print(f"creep {creep:.2e} m/s (ε_v = 1e-3 m/s)")


def test_box_slides_on_a_fixed_inclined_box_with_coulomb_acceleration(wc):
    """The incline as a fixed, rotated box (mesh–mesh contact, normal gravity): the box on
    it accelerates at g (sin θ − μ cos θ) along the slope within 2 %."""
    tan_theta, mu = 0.7, 0.5
    theta = np.arctan(tan_theta)
    R = rotation_y(-theta)  # `along` (the slope's x axis) points uphill
    scene = abdsim.Scene(dt=DT, friction=mu)
    slope = wc.box((2.0, 0.6, 0.2))
    wc.place(slope, [[0.0, 0.0, 0.0]], R[None])
    slope.instances["is_fixed"] = np.array([1])
    scene.add(slope)
    box = wc.box((0.1, 0.1, 0.1))
    normal, along = R @ [0, 0, 1], R @ [1, 0, 0]
    wc.place(box, [0.5 * along + (0.1 + 0.05 + 0.0005) * normal], R[None])  # 0.5 m uphill
    h = scene.add(box)
    world = abdsim.World(scene)
    world.step(30)
    t, s = [], []
    for _ in range(60):
        world.step()
        t.append(world.time)
        s.append(-world.velocities()[h.start, :3, 3] @ along)  # downhill speed
        hits, d_min, _ = wc.coal_check(world)
        assert hits == 0 and d_min > 0
    a = np.polyfit(t, s, 1)[0]
    expected = G * (np.sin(theta) - mu * np.cos(theta))
    assert a == pytest.approx(expected, rel=0.02)
    print(f"on a fixed slope: a = {a:.4f} m/s², closed form {expected:.4f}")


# -- contact table ----------------------------------------------------------------------------
def test_contact_table_friction_per_pair(wc):
    """Two boxes on the incline (tan θ = 0.7), elements 1 and 2: μ = 0.2 against the ground
    for element 1 slides at g (sin θ − 0.2 cos θ); μ = 0.8 for element 2 sticks."""
    world, h, theta = incline_world(
        wc, 0.7, n=2, elements=[1, 2], table=[(1, abdsim.GROUND, 0.2), (2, "ground", 0.8)]
    )
    a = sliding_acceleration(world, body=0)
    assert a == pytest.approx(G * (np.sin(theta) - 0.2 * np.cos(theta)), rel=0.02)
    assert abs(world.velocities()[1, 0, 3]) < 1e-3  # the μ = 0.8 box only creeps


def test_ground_friction_and_disabled_pairs(wc):
    """add_ground(friction=...) sets μ against the ground; a pair disabled in the contact
    table passes through (a box falls through a fixed plate onto the ground), while the
    same scene with the pair enabled rests on the plate."""
    tan_theta = 0.7
    theta = np.arctan(tan_theta)
    gravity = G * np.array([np.sin(theta), 0.0, -np.cos(theta)])
    scene = abdsim.Scene(dt=DT, gravity=gravity, friction=0.9)
    scene.add_ground(0.0, friction=0.2)
    sc = wc.box((0.1, 0.1, 0.1))
    wc.place(sc, [[0.0, 0.0, 0.0505]])
    scene.add(sc)
    a = sliding_acceleration(abdsim.World(scene))
    assert a == pytest.approx(G * (np.sin(theta) - 0.2 * np.cos(theta)), rel=0.02)

    finals = {}
    for enabled in (True, False):
        scene = abdsim.Scene(dt=DT)
        scene.add_ground(0.0)
        plate = wc.box((0.5, 0.5, 0.02))
        wc.place(plate, [[0.0, 0.0, 0.2]])
        plate.instances["is_fixed"] = np.array([1])
        scene.add(plate, contact_element=1)
        box = wc.box((0.1, 0.1, 0.1))
        wc.place(box, [[0.0, 0.0, 0.35]])
        h = scene.add(box, contact_element=2)
        scene.contact_table.set(1, 2, enabled=enabled)
        world = abdsim.World(scene)
        world.step(100)
        finals[enabled] = world.vertices(h)[0][:, 2].min()
    assert 0.21 < finals[True] <= 0.21 + D_HAT  # on the plate
    assert 0 < finals[False] <= D_HAT  # through it, on the ground


# -- self collision, shells and rods ------------------------------------------------------------
def two_box_body(gap):
    """One body made of two 5 cm boxes `gap` apart along x."""
    a = trimesh.creation.box(extents=(0.05, 0.05, 0.05))
    b = a.copy()
    a.apply_translation([-0.025 - gap / 2, 0, 0])
    b.apply_translation([0.025 + gap / 2, 0, 0])
    return trimesh.util.concatenate([a, b])


def test_self_collision_flag(wc):
    """A body whose surface has two parts 0.5 mm apart: with self_collision = 1 the two parts
    are an active contact pair of the body with itself; with 0 they are not. Parts that
    overlap are an invalid start only when self-collision is on."""
    pairs = {}
    for flag in (0, 1):
        sc = wc.solid(two_box_body(0.0005))
        sc.meta["self_collision"] = np.int32(flag)
        sc2 = wc.box((0.05, 0.05, 0.05))
        wc.place(sc2, [[0.0, 0.0, 0.5]])  # a second body, far away
        scene = abdsim.Scene(dt=DT, gravity=(0, 0, 0))
        scene.add(sc)
        scene.add(sc2)
        world = abdsim.World(scene)
        V = np.zeros((1, 4, 4))
        V[0, :3, :3] = [[0, -2.0, 0], [2.0, 0, 0], [0, 0, 0]]  # spinning about z
        world.set_state(velocities=np.concatenate([V, np.zeros((1, 4, 4))]))
        d = world.step(20)
        pairs[flag] = d.contact_pairs["point_triangle"] + d.contact_pairs["edge_edge"]
        if flag:
            assert 0 < d.min_contact_distance <= 0.0005 + 1e-6
    assert pairs[0] == 0 and pairs[1] > 0
    overlapping = wc.solid(two_box_body(-0.01))
    overlapping.meta["self_collision"] = np.int32(1)
    scene = abdsim.Scene(dt=DT)
    scene.add(overlapping)
    with pytest.raises(ValueError, match="bodies 0 and 0"):
        abdsim.World(scene)


def test_rod_and_shell_collide_through_their_thickness(wc):
    """A rod (radius 5 mm) dropped on the ground rests with its centre line 5 mm + (0, d̂]
    above it; a shell (thickness radius 2 mm) dropped on a fixed box rests with its
    mid-surface 2 mm + (0, d̂] above the box."""
    scene = abdsim.Scene(dt=DT)
    scene.add_ground(0.0)
    rod = abdsim.geometry.edge_mesh(
        np.array([[-0.2, 0, 0], [0, 0, 0], [0.2, 0, 0]], float), np.array([[0, 1], [1, 2]])
    )
    abdsim.AffineBodyRod().apply_to(rod, kappa=1e8, thickness=0.005)
    wc.place(rod, [[0.0, 0.0, 0.05]])
    h_rod = scene.add(rod)
    table = wc.box((0.4, 0.4, 0.1))
    wc.place(table, [[1.0, 0.0, 0.05]])
    table.instances["is_fixed"] = np.array([1])
    scene.add(table)
    verts = np.array([[x, y, 0.0] for x in (-0.1, 0, 0.1) for y in (-0.1, 0, 0.1)])
    tris = []
    for i in range(2):
        for j in range(2):
            a, b, c, e = 3 * i + j, 3 * i + j + 1, 3 * (i + 1) + j, 3 * (i + 1) + j + 1
            tris += [[a, c, b], [b, c, e]]
    sheet = abdsim.geometry.triangle_mesh(verts, np.array(tris))
    abdsim.AffineBodyShell().apply_to(sheet, kappa=1e8, thickness=0.002)
    wc.place(sheet, [[1.0, 0.0, 0.15]])
    h_sheet = scene.add(sheet)
    world = abdsim.World(scene)
    world.step(60)
    z_rod = world.vertices(h_rod)[0][:, 2]
    z_sheet = world.vertices(h_sheet)[0][:, 2] - 0.1
    assert np.all((z_rod > 0.005) & (z_rod <= 0.005 + D_HAT)), z_rod
    assert np.all((z_sheet > 0.002) & (z_sheet <= 0.002 + D_HAT)), z_sheet
    assert vertex_speed(world, h_rod) < 1e-4 and vertex_speed(world, h_sheet) < 1e-4


def test_invalid_initial_configurations_are_refused_with_the_bodies_named(wc):
    scene = abdsim.Scene(dt=DT)
    sc = wc.box((0.1, 0.1, 0.1), n=2)
    wc.place(sc, [[0, 0, 0.3], [0.05, 0, 0.3]])  # overlapping
    scene.add(sc)
    with pytest.raises(ValueError, match="bodies 0 and 1 intersect"):
        abdsim.World(scene)
    scene = abdsim.Scene(dt=DT)
    scene.add_ground(0.0)
    rod = abdsim.geometry.edge_mesh(np.array([[-0.1, 0, 0], [0.1, 0, 0.0]]), np.array([[0, 1]]))
    abdsim.AffineBodyRod().apply_to(rod, kappa=1e8, thickness=0.01)
    wc.place(rod, [[0, 0, 0.005]])  # closer to the ground than its radius
    scene.add(rod)
    with pytest.raises(ValueError, match="body 0 reaches into the ground"):
        abdsim.World(scene)
    scene = abdsim.Scene(dt=DT)
    sc = wc.box((0.1, 0.1, 0.1), n=2)
    wc.place(sc, [[0, 0, 0.3], [0.1, 0, 0.3]])  # touching: no gap at all
    scene.add(sc)
    with pytest.raises(ValueError, match="bodies 0 and 1"):
        abdsim.World(scene)
    scene = abdsim.Scene(dt=DT, contact=False)  # without contact the same is fine
    scene.add(sc)
    abdsim.World(scene).step()


# -- kinematic bodies ---------------------------------------------------------------------------
def test_kinematic_pusher_pushes_a_box_without_penetrating_it(wc):
    """A scripted 10 cm block moving at 0.5 m/s pushes a resting 10 cm box along the ground
    (μ = 0.5) for a second: coal never finds an intersection, the box is pushed ahead of
    the pusher (about the pusher's travel), and the pusher follows its script to within
    the reported lag."""
    world, hp, hb = wc.pushing_world(0.5)
    lags = []
    for _ in range(100):
        d = world.step()
        lags.append(d.kinematic_lag)
        hits, d_min, low = wc.coal_check(world)
        assert hits == 0 and d_min > 0 and low > 0
    x_p = world.transforms()[hp.start, 0, 3]
    x_b = world.transforms()[hb.start, 0, 3]
    assert x_p == pytest.approx(-0.12 + 0.5, abs=max(lags) + 1e-9)
    assert 0.1 < x_b - x_p < 0.1 + 0.01  # ahead of the pusher, close to it
    assert x_b > 0.35  # pushed most of the way
    assert world.is_kinematic(hp.start)
    print(f"box pushed {x_b:.3f} m, pusher at {x_p:.4f} m, largest lag {max(lags):.2e} m")


def test_kinematic_fingers_squeeze_and_lift_a_box(wc):
    """Two scripted fingers close on a box (their targets 1 cm inside it), then lift: the
    fingers are driven (stopped by the barrier, lag reported), the box rises with them by
    friction, and nothing ever intersects."""
    scene = abdsim.Scene(dt=DT, friction=0.8)
    scene.add_ground(0.0)
    fingers = wc.box((0.02, 0.06, 0.06), n=2)
    wc.place(fingers, [[-0.07, 0, 0.05], [0.07, 0, 0.05]])
    hf = scene.add(fingers, kinematic=True)
    box = wc.box((0.08, 0.08, 0.08), density=200)
    wc.place(box, [[0.0, 0.0, 0.0405]])
    hb = scene.add(box)
    world = abdsim.World(scene)
    T0 = world.transforms()[hf.start : hf.stop]

    def targets(t):
        T = T0.copy()
        close = min(t / 0.2, 1.0) * 0.03  # 3 cm in: 1 cm past the box's faces
        T[0, 0, 3] += close
        T[1, 0, 3] -= close
        T[:, 2, 3] += max(t - 0.3, 0.0) * 0.2  # then up at 0.2 m/s
        return T

    z0 = world.transforms()[hb.start, 2, 3]
    lag = 0.0
    for _ in range(60):
        world.set_kinematic_targets([hf.start, hf.start + 1], targets(world.core.next_time))
        d = world.step()
        lag = max(lag, d.kinematic_lag)
        hits, d_min, _ = wc.coal_check(world)
        assert hits == 0 and d_min > 0
    assert d.driven_bodies == 2 and 0.009 < d.kinematic_lag < 0.011
    lift = world.transforms()[hb.start, 2, 3] - z0
    finger_lift = world.transforms()[hf.start, 2, 3] - T0[0, 2, 3]
    assert finger_lift == pytest.approx(0.06, abs=1e-3)
    assert lift == pytest.approx(finger_lift, abs=5e-3)  # carried by friction
    print(f"box lifted {lift:.4f} m with the fingers ({finger_lift:.4f} m), lag {lag:.4f} m")


# -- determinism -----------------------------------------------------------------------------
def test_contact_steps_are_bit_identical_across_runs_and_threads(wc):
    def run(threads):
        scene = abdsim.Scene(dt=DT, num_threads=threads)
        scene.add_ground(0.0)
        rng = np.random.default_rng(3)
        sc = wc.solid(trimesh.creation.torus(0.04, 0.012, major_sections=12, minor_sections=6), 4)
        R = [
            trimesh.transformations.random_rotation_matrix(rng.random(3))[:3, :3] for _ in range(4)
        ]
        wc.place(sc, [[0.0, 0.0, 0.06 + 0.1 * k] for k in range(4)], np.array(R))
        scene.add(sc)
        box = wc.box((0.05, 0.05, 0.05), n=70)  # enough bodies for the parallel loops
        wc.place(box, [[0.2 + 0.1 * (k % 10), 0.1 * (k // 10), 0.03] for k in range(70)])
        scene.add(box)
        world = abdsim.World(scene)
        world.step(40)
        return world.q, world.q_dot

    q1, v1 = run(0)
    q2, v2 = run(0)
    q3, v3 = run(1)
    np.testing.assert_array_equal(q1, q2)
    np.testing.assert_array_equal(v1, v2)
    np.testing.assert_array_equal(q1, q3)
    np.testing.assert_array_equal(v1, v3)
