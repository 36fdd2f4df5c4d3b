"""MJCF bodies moved by several joints, as chains of joint frames (articulated loads).

abdsim joins two bodies by one joint. MuJoCo applies a body's joints ``j1..jk`` in order, each
about its own ``pos``/``axis`` in the body frame as moved by the joints before it (dm_control's
planar roots ``rootx, rootz, rooty``, two- and three-hinge hips, ``point_mass``'s two slides).
The loader makes that a chain ``parent -j1-> frame1 -j2-> ... -jk-> body``: ``frame_i`` is the
body frame after ``j1..ji`` (MuJoCo's body pose with the later joints at ``qpos0``, and its
velocity with their ``qvel`` at zero), so each abdsim joint is the MuJoCo joint exactly and
the frames add no joint coordinates.

A frame is an affine body that collides with nothing (its surface is the body's equivalent
inertia box, ``bridges/_inertia_proxy.py``, which only gives it a volume). It carries a
fraction :data:`FRAME_MASS_FRACTION` of the body's mass and inertia (same centre), taken from
the body, so the totals stay the source's; the dynamics then differ from MuJoCo's by that
fraction of the body's inertia moving with the partial joint set (measured in
``tests/bridges/test_compound_joints.py``). A massless frame has no affine-body model (a
singular 12x12 mass).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from abdsim.bridges._bodies import (
    LoadedBody,
    make_body,
    pose_matrix,
    velocity_matrix,
)
from abdsim.bridges._inertia_proxy import inertia_box

#: Fraction of a body's mass and inertia each of its joint frames carries, chosen by
#: measurement. The dynamics error grows linearly with it (humanoid against MuJoCo RK4 over
#: 0.5 s: 2.1e-3 rad at 1e-2, 2.2e-4 at 1e-3, 5.9e-5 at 1e-4, where BDF2's own error at
#: dt = 1e-3 dominates). Newton converged on every dm_control file at 1e-3 and at 1e-4 (600
#: steps with contact, at most 50 iterations a step but for one humanoid step at 1e-3 that
#: needed 238 and a halved step; frame-to-neighbour mass ratios up to 5e5 in fish). 1e-4 keeps
#: a frame at the 1e4 mass ratio the joints promise against its own body.
FRAME_MASS_FRACTION = 1e-4


def frame_state(mujoco, model, qpos, qvel, body: int, upto: int) -> tuple[np.ndarray, np.ndarray]:
    """World pose and dT/dt of MuJoCo ``body``'s frame after its first ``upto`` joints, at
    ``qpos``/``qvel``: MuJoCo's own kinematics with the body's later joints at ``qpos0`` (an
    identity) and their velocities at zero."""
    d = mujoco.MjData(model)
    d.qpos[:] = qpos
    d.qvel[:] = qvel
    adr, num = int(model.body_jntadr[body]), int(model.body_jntnum[body])
    for j in range(adr + upto, adr + num):
        qa, da = int(model.jnt_qposadr[j]), int(model.jnt_dofadr[j])
        nq, nv = _sizes(mujoco, model, j)
        d.qpos[qa : qa + nq] = model.qpos0[qa : qa + nq]
        d.qvel[da : da + nv] = 0.0
    mujoco.mj_kinematics(model, d)
    mujoco.mj_comPos(model, d)
    mujoco.mj_comVel(model, d)
    res = np.zeros(6)
    mujoco.mj_objectVelocity(model, d, mujoco.mjtObj.mjOBJ_XBODY, body, res, 0)
    R = np.array(d.xmat[body]).reshape(3, 3)
    return pose_matrix(R, d.xpos[body]), velocity_matrix(R, res[:3], res[3:])


def _sizes(mujoco, model, j: int) -> tuple[int, int]:
    kind = mujoco.mjtJoint(int(model.jnt_type[j]))
    return {
        mujoco.mjtJoint.mjJNT_FREE: (7, 6),
        mujoco.mjtJoint.mjJNT_BALL: (4, 3),
    }.get(kind, (1, 1))


def joint_frames(loader, body: LoadedBody, source_body: int) -> list[LoadedBody]:
    """The joint frames of ``body`` (MuJoCo body ``source_body``, k > 1 joints, none of them
    free: MuJoCo refuses a free joint with others, more than 6 dofs): k - 1 bodies, frame i
    after the first i joints. ``body``'s mass properties lose what the frames carry."""
    mj, m, d = loader.mj, loader.m, loader.d
    adr, num = int(m.body_jntadr[source_body]), int(m.body_jntnum[source_body])
    names = [m.joint(j).name or f"joint{j}" for j in range(adr, adr + num)]
    from abdsim.constitution.rigid_body import assign_rigid_body, to_rigid_body

    rigid = to_rigid_body(body.geometry)
    share = FRAME_MASS_FRACTION
    mass = (share * rigid.mass, rigid.mass_center, share * rigid.inertia)
    frames = []
    for i in range(1, num):
        name = f"{body.name} (joint frame after {names[i - 1]!r})"
        T, V = frame_state(mj, m, d.qpos, d.qvel, source_body, i)
        frame = make_body(
            name,
            body.kind,
            [inertia_box(name, *mass)],
            T,
            kappa=loader.kappa,
            constitution=loader.constitution,
            mass=mass,
            velocity=V,
            links=(),
            joint=names[i - 1],
        )
        # A frame has no geom: MuJoCo's filter pairs it with nothing (bridges/_contact_rules).
        frames.append(replace(frame, geoms=(), geom_ranges={}, friction=None))
    keep = 1.0 - share * (num - 1)
    assign_rigid_body(body.geometry, keep * rigid.mass, rigid.mass_center, keep * rigid.inertia)
    return frames


def compound_note(bodies: list[str]) -> str:
    """The load note naming the bodies that became joint-frame chains."""
    return (
        f"bodies moved by several joints {bodies}: each hangs from its parent through a chain "
        "of joint frames (one joint each, in MuJoCo's order; affine bodies that collide with "
        f"nothing, each carrying {FRAME_MASS_FRACTION:g} of the body's mass and inertia, taken "
        "from the body); the joints and their coordinates are MuJoCo's"
    )
