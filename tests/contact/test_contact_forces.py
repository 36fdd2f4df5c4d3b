"""Contact forces out of the World (``World.contacts``, ``World.contact_wrenches``) against
closed forms (weight, Coulomb friction on an incline and under a pusher) and against the
momentum change each step applied, recomputed here from the states and the mass matrix
(BDF1 and BDF2), force and torque."""

import ipctk
import numpy as np
import pytest

import abdsim

DT = 0.01
G = 9.81
# Tight Newton tolerances where a test compares forces to 1e-4 or better: static friction is
# a spring of stiffness μλ/(ε_v h) (~5e5 N/m here), so the default step tolerance leaves a
# force residual of ~1 % of the weight on a sticking box (the readout itself is exact).
TIGHT = dict(newton_tol_translation=1e-7, newton_tol_affine=1e-6)


def rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def pair_force_sums(contacts, n):
    """(n, 3): per body, the sum of the pair forces it takes (+ first side, − second)."""
    f = np.zeros((n, 3))
    np.add.at(f, contacts.bodies[:, 0], contacts.forces)
    second = contacts.bodies[:, 1] >= 0
    np.add.at(f, contacts.bodies[second, 1], -contacts.forces[second])
    return f


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_resting_box_normal_forces_sum_to_its_weight(wc, integrator):
    """A 3 kg box at rest on the ground: four corner contacts (bodies (0, -1), normals +z,
    points under the corners), normal forces summing to m g within 1e-6, no torque."""
    scene = abdsim.Scene(dt=DT, integrator=integrator)
    scene.add_ground(0.0)
    sc = wc.box((0.2, 0.15, 0.1))
    wc.place(sc, [[0.0, 0.0, 0.0505]])
    h = scene.add(sc)
    world = abdsim.World(scene)
    m = world.core.mass_matrix(0)[0, 0]
    world.step(100)
    c = world.contacts()
    assert len(c) == 4
    assert (c.bodies == [0, -1]).all()
    np.testing.assert_allclose(c.normals, np.tile([0.0, 0.0, 1.0], (4, 1)))
    corners = world.vertices(h)[0]
    corners = corners[corners[:, 2] < 0.01]
    np.testing.assert_allclose(np.sort(c.points[:, :2], axis=0), np.sort(corners[:, :2], axis=0))
    assert (c.points[:, 2] > 0).all() and (c.points[:, 2] < corners[:, 2]).all()
    assert c.normal_force.sum() == pytest.approx(m * G, rel=1e-6)
    # Each corner's stored energy is κ b(d²) with ipctk's barrier at its height d, and its
    # force −2 d κ b'(d²) (friction's potential is not stored energy: not in barrier_energy).
    kappa, d_hat = world.contact.kappa, 1e-3
    for point, force, energy in zip(c.points, c.normal_force, c.barrier_energy, strict=True):
        d = corners[np.argmin(np.linalg.norm(corners[:, :2] - point[:2], axis=1)), 2]
        assert energy == pytest.approx(kappa * ipctk.barrier(d * d, d_hat**2), rel=1e-9)
        b1 = ipctk.barrier_first_derivative(d * d, d_hat**2)
        assert force == pytest.approx(-2 * d * kappa * b1, rel=1e-9)
    W = world.contact_wrenches()
    assert W.shape == (1, 6)
    np.testing.assert_allclose(W[0, :3], [0.0, 0.0, m * G], rtol=1e-6, atol=1e-6 * m * G)
    np.testing.assert_allclose(W[0, 3:], 0.0, atol=1e-6 * m * G * 0.1)  # N m: weight × 0.1 m
    print(f"{integrator}: Σ normal force / m g − 1 = {c.normal_force.sum() / (m * G) - 1:.1e}")


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_friction_on_an_incline_below_the_friction_angle_holds_the_box(wc, integrator):
    """tan θ = 0.3 < μ = 0.5 (gravity tilted by θ): the friction force equals m g sin θ up
    the slope within 1e-4, the normal force m g cos θ within 1e-6."""
    theta = np.arctan(0.3)
    gravity = G * np.array([np.sin(theta), 0.0, -np.cos(theta)])
    scene = abdsim.Scene(dt=DT, gravity=gravity, friction=0.5, integrator=integrator, **TIGHT)
    scene.add_ground(0.0)
    sc = wc.box((0.1, 0.1, 0.1))
    wc.place(sc, [[0.0, 0.0, 0.0505]])
    scene.add(sc)
    world = abdsim.World(scene)
    m = world.core.mass_matrix(0)[0, 0]
    world.step(60)
    c = world.contacts()
    friction = c.friction_force.sum(axis=0)
    assert friction[0] == pytest.approx(-m * G * np.sin(theta), rel=1e-4)
    assert abs(friction[1]) < 1e-9 and abs(friction[2]) < 1e-9
    assert c.normal_force.sum() == pytest.approx(m * G * np.cos(theta), rel=1e-6)
    np.testing.assert_allclose(world.contact_wrenches()[0, :3], -m * gravity, rtol=1e-4)
    ratio = -friction[0] / (m * G * np.sin(theta))
    print(f"{integrator}: friction / m g sin θ − 1 = {ratio - 1:.1e}")


def test_kinematic_pusher_force_is_the_wrench_it_applies(wc):
    """A scripted block pushes a 1 kg box along the ground (μ = 0.5) at 0.2 m/s. The pairs
    between them sum to the pusher's wrench (opposite) and, at steady sliding, to Coulomb's
    μ (m g + the pusher's downward push) along the motion within 1e-6; the box's own wrench
    (pusher + ground) is its momentum change."""
    world, hp, hb = wc.pushing_world(0.2, **TIGHT)
    p, b = hp.start, hb.start
    m = world.core.mass_matrix(b)[0, 0]
    world.step(40)
    v0 = world.q_dot[b, :3].copy()
    world.step()
    c = world.contacts()
    W = world.contact_wrenches()
    between = {tuple(x) for x in c.bodies.tolist()} - {(b, -1)}
    assert between and between <= {(p, b), (b, p)}
    on_box = pair_force_sums(c.select(c.bodies[:, 1] != -1), 2)[b]
    np.testing.assert_allclose(on_box, -W[p, :3], rtol=1e-9, atol=1e-12)
    assert world.q_dot[b, 0] == pytest.approx(0.2, rel=1e-6)  # sliding steadily
    assert on_box[0] == pytest.approx(0.5 * (m * G - on_box[2]), rel=1e-6)
    momentum = m * (world.q_dot[b, :3] - v0) / DT - m * np.array([0.0, 0.0, -G])
    np.testing.assert_allclose(W[b, :3], momentum, atol=1e-6 * m * G)
    print(f"push {on_box[0]:.6f} N, μ (m g + push down) {0.5 * (m * G - on_box[2]):.6f} N")


def momentum_change(M, q_hist, v_hist, gravity, order):
    """M (q − q̃)/c² of the last step from the states (order: the step's integrator order,
    1 or 2): what the contact force must equal on a body whose potentials exert no net force
    or torque of their own."""
    g = np.zeros(12)
    g[:3] = gravity
    if order == 1:
        return M @ ((v_hist[-1] - v_hist[-2]) / DT - g)
    c = 2 * DT / 3
    q_hat = (4 * q_hist[-2] - q_hist[-3]) / 3
    v_hat = (4 * v_hist[-2] - v_hist[-3]) / 3
    return M @ (((q_hist[-1] - q_hat) / c - v_hat) / c - g)


def torque_of(q, generalized):
    """Torque about the centre of mass (at x̄ = 0) of a generalized force on q = [p, A]:
    Σ (A x̄) × f = axial(A Gᵀ) with G = ∂/∂A; the shape energy, invariant under rotations
    of A, has none."""
    A = q[3:].reshape(3, 3)
    T = A @ generalized[3:].reshape(3, 3).T
    return np.array([T[1, 2] - T[2, 1], T[2, 0] - T[0, 2], T[0, 1] - T[1, 0]])


@pytest.mark.parametrize(
    "obstacle, integrator, damping",
    [
        ("ground", "bdf1", 0.0),
        ("ground", "bdf2", 0.0),
        ("box", "bdf1", 0.0),
        ("ground", "bdf2", 1.0),
        ("box", "bdf1", 1.0),
    ],
)
def test_wrench_is_the_momentum_change_the_step_applied(wc, obstacle, integrator, damping):
    """A spinning box lands with friction on the ground or on a fixed box (point–triangle
    and edge–edge pairs): at every contact step its wrench equals M (q − q̃)/c² (force) and
    that generalized force's torque about the centre of mass, within 1e-8 of the peak; the
    pairs of ``contacts()`` sum to the wrenches' forces. With contact damping the dampers'
    forces are part of both."""
    scene = abdsim.Scene(dt=DT, integrator=integrator, contact_damping=damping, **TIGHT)
    if obstacle == "ground":
        scene.add_ground(0.0)
    else:
        base = wc.box((1.0, 1.0, 0.2))
        wc.place(base, [[0.0, 0.0, -0.1]])
        base.instances["is_fixed"] = np.array([1])
        scene.add(base)
    R = rotation([1, 2, 0.5], 0.6)
    sc = wc.box((0.2, 0.15, 0.1))
    wc.place(sc, [[0.0, 0.0, 0.2]], R[None])
    V = np.zeros((1, 4, 4))
    V[0, :3, 3] = [0.5, 0.0, -1.0]
    V[0, :3, :3] = np.array([[0, -3, 1], [3, 0, -2], [-1, 2, 0.0]]) @ R  # Ȧ = ω× A
    sc.instances["velocity"] = V
    b = scene.add(sc).start
    world = abdsim.World(scene)
    M = world.core.mass_matrix(b)
    q_hist, v_hist = [world.q[b].copy()], [world.q_dot[b].copy()]
    errors, peak, kinds = [], 0.0, set()
    for _ in range(60):
        d = world.step()
        q_hist.append(world.q[b].copy())
        v_hist.append(world.q_dot[b].copy())
        W = world.contact_wrenches()
        if not W[b].any():
            continue
        kinds |= {k for k, v in d.contact_pairs.items() if v}
        F = momentum_change(M, q_hist, v_hist, scene.gravity, d.integrator_order)
        errors.append(np.abs(W[b] - np.concatenate([F[:3], torque_of(q_hist[-1], F)])).max())
        peak = max(peak, np.abs(W[b]).max())
        c = world.contacts()
        np.testing.assert_allclose(
            pair_force_sums(c, world.num_bodies), W[:, :3], atol=1e-12 * peak
        )
    assert len(errors) > 30 and peak > 50
    expected = {"point_ground"} if obstacle == "ground" else {"point_triangle", "edge_edge"}
    assert expected <= kinds and "friction" in kinds
    assert max(errors) < 1e-8 * peak
    print(
        f"{obstacle}/{integrator}: {len(errors)} contact steps, peak {peak:.1f}, "
        f"largest difference {max(errors):.1e}"
    )


def test_no_contact_gives_empty_arrays(wc):
    """Without contact (disabled, or nothing near) the arrays are empty / zero."""
    scene = abdsim.Scene(dt=DT, contact=False)
    scene.add(wc.box((0.1, 0.1, 0.1)))
    world = abdsim.World(scene)
    world.step()
    c = world.contacts()
    assert len(c) == 0 and c.bodies.shape == (0, 2) and c.friction_force.shape == (0, 3)
    np.testing.assert_array_equal(world.contact_wrenches(), np.zeros((1, 6)))
    scene = abdsim.Scene(dt=DT)
    scene.add_ground(0.0)
    sc = wc.box((0.1, 0.1, 0.1))
    wc.place(sc, [[0.0, 0.0, 1.0]])
    scene.add(sc)
    world = abdsim.World(scene)
    world.step()
    assert len(world.contacts()) == 0 and not world.contact_wrenches().any()


def test_bad_input_to_the_contact_force_bindings_is_a_value_error(wc):
    """Wrong sizes and an intersecting state raise ValueError (never a crash)."""
    scene = abdsim.Scene(dt=DT)
    scene.add_ground(0.0)
    sc = wc.box((0.1, 0.1, 0.1))
    wc.place(sc, [[0.0, 0.0, 0.0505]])
    scene.add(sc)
    world = abdsim.World(scene)
    term, q = world.contact, world.q.reshape(-1)
    with pytest.raises(ValueError, match="12 values per body"):
        term.contact_forces(q[:5])
    with pytest.raises(ValueError, match="12 values per body"):
        term.contact_wrenches(q[:5], np.zeros((1, 3)))
    with pytest.raises(ValueError, match="one point per body"):
        term.contact_wrenches(q, np.zeros((2, 3)))
    below = q.copy()
    below[2] = 0.01  # half inside the ground
    with pytest.raises(ValueError, match="infeasible"):
        term.contact_forces(below)
    with pytest.raises(ValueError, match="infeasible"):
        term.contact_wrenches(below, np.zeros((1, 3)))
