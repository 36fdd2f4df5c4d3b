"""Helpers for the joint tests: box links hanging from their joint, and an independent
reference (Pinocchio's ABA integrated with RK4 at a fine step) for planar chains."""

from __future__ import annotations

import numpy as np

import abdsim

LINK = (0.05, 0.05, 1.0)  # box link: 5 cm square section, 1 m long along its z axis


def rot_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def link(kappa: float = 1e10, density: float = 1e3, extents=LINK) -> abdsim.SimplicialComplex:
    """A box whose body origin is at its top end (the joint) and hangs along −z."""
    box = abdsim.geometry.box(extents)
    sc = abdsim.geometry.triangle_mesh(
        box.positions - np.array([0.0, 0.0, extents[2] / 2]), box.triangles
    )
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=kappa, mass_density=density)
    return sc


def chain_scene(
    angles,
    kappa: float = 1e10,
    densities=None,
    dt: float = 1e-3,
    integrator: str = "bdf2",
    **settings,
):
    """A planar chain of hanging links joined by hinges about y, the first to the world at
    the origin; `angles` are the relative joint angles at load. Returns (scene, handles)."""
    scene = abdsim.Scene(dt=dt, integrator=integrator, contact=False, **settings)
    densities = densities or [1e3] * len(angles)
    handles, parent, top, total = [], None, np.zeros(3), 0.0
    for i, (a, rho) in enumerate(zip(angles, densities, strict=True)):
        total += a
        sc = link(kappa, rho)
        T = np.eye(4)
        T[:3, :3] = rot_y(total)
        T[:3, 3] = top
        sc.transforms = T[None]
        h = scene.add(sc)
        scene.add_joint("revolute", parent, h, anchor=top, axis=(0, 1, 0), name=f"j{i}")
        handles.append(h)
        parent = h
        top = top + rot_y(total) @ np.array([0.0, 0.0, -LINK[2]])
    return scene, handles


def pin_inertia(sc: abdsim.SimplicialComplex):
    """Pinocchio's spatial inertia of a body, from abdsim.to_rigid_body (its rest frame)."""
    import pinocchio as pin

    rb = abdsim.to_rigid_body(sc)
    return pin.Inertia(float(rb.mass), np.asarray(rb.mass_center), np.asarray(rb.inertia))


def pinocchio_chain(handles):
    """The same chain in Pinocchio (revolute-y joints, each link's mass, centre of mass and
    inertia from abdsim.to_rigid_body)."""
    import pinocchio as pin

    model = pin.Model()
    parent = 0
    for i, h in enumerate(handles):
        placement = pin.SE3(np.eye(3), np.array([0.0, 0.0, -LINK[2] if i else 0.0]))
        parent = model.addJoint(parent, pin.JointModelRY(), placement, f"j{i}")
        model.appendBodyToJoint(parent, pin_inertia(h.sc), pin.SE3.Identity())
    return model


def aba_rk4(model, q0, v0, t_end: float, h: float, sample_every: int, velocities=False, tau=None):
    """RK4 on (q, v) with Pinocchio's ABA (zero torque), configurations advanced with
    pin.integrate (on the manifold, for ball joints); samples q (and v) every
    `sample_every` steps."""
    import pinocchio as pin

    data = model.createData()
    zero = np.zeros(model.nv)

    def acc(q, v):
        return pin.aba(model, data, q, v, zero if tau is None else tau(q, v))

    q, v = np.array(q0, float), np.array(v0, float)
    qs, vs = [q.copy()], [v.copy()]
    for k in range(1, int(round(t_end / h)) + 1):
        a1 = acc(q, v)
        v2 = v + 0.5 * h * a1
        a2 = acc(pin.integrate(model, q, 0.5 * h * v), v2)
        v3 = v + 0.5 * h * a2
        a3 = acc(pin.integrate(model, q, 0.5 * h * v2), v3)
        v4 = v + h * a3
        a4 = acc(pin.integrate(model, q, h * v3), v4)
        q = pin.integrate(model, q, h / 6 * (v + 2 * v2 + 2 * v3 + v4))
        v = v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        if k % sample_every == 0:
            qs.append(q.copy())
            vs.append(v.copy())
    return (np.array(qs), np.array(vs)) if velocities else np.array(qs)


def _robots_dir():
    import sys
    from pathlib import Path

    for entry in sys.path:
        candidate = Path(entry or ".") / "cmeel.prefix/share/example-robot-data/robots"
        if candidate.is_dir():
            return candidate
    return None


def robot_model(description: str, filename: str):
    """Pinocchio's fixed-base model of an example-robot-data URDF (None if not installed)."""
    import pinocchio as pin

    robots = _robots_dir()
    path = None if robots is None else robots / description / "urdf" / filename
    if path is None or not path.is_file():
        return None
    return pin.buildModelFromUrdf(str(path))
