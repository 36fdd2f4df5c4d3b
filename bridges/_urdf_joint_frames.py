"""URDF joints that hang from massless links without geometry, as joint frames (articulated loads).

URDFs build multi-axis joints (hips, shoulders, wrists) as chains of revolute joints through
links with neither mass nor geometry (example-robot-data's ``human.urdf``: ``left_hip_Z`` moves
``left_upperleg_virtual``, ``left_hip_X`` moves ``left_upperleg_virtual_2``, ``left_hip_Y`` moves
``left_upperleg``). Pinocchio gives such a link's joint a zero inertia; an affine body needs a
mass (a massless one has a singular 12x12 mass matrix). As for MJCF bodies with several joints
(``bridges/_joint_frames.py``), each such group becomes a *joint frame*: an affine body that
collides with nothing, posed at its joint frame, carrying :data:`FRAME_MASS_FRACTION` of the
mass and inertia of the first massive group below it (the *donor*; same centre of mass), taken
from the donor so the robot's totals stay the source's. The joints and their coordinates are
the URDF's; the dynamics differ from Pinocchio's by that fraction of the donor's inertia moving
with the partial joint set (measured in ``tests/bridges/test_urdf_joint_frames.py``).
"""

from __future__ import annotations

import numpy as np

from abdsim.bridges._joint_frames import FRAME_MASS_FRACTION

MassProperties = tuple[float, np.ndarray, np.ndarray]


def frame_donors(model, has_geometry: set[int]) -> dict[int, int]:
    """Pinocchio joints (> 0) whose group has no mass and no geometry but carries a joint below
    it, each with its donor: the first joint below it (depth first, through such groups only)
    whose group has mass. A group with no massive group below it gets no frame."""
    children: dict[int, list[int]] = {}
    for j in range(1, model.njoints):
        children.setdefault(int(model.parents[j]), []).append(j)

    def massless(j: int) -> bool:
        return model.inertias[j].mass <= 0 and j not in has_geometry

    def donor(j: int) -> int | None:
        for c in children.get(j, []):
            if model.inertias[c].mass > 0:
                return c
            if massless(c) and (d := donor(c)) is not None:
                return d
        return None

    out = {}
    for j in range(1, model.njoints):
        if massless(j) and children.get(j) and (d := donor(j)) is not None:
            out[j] = d
    return out


def frame_mass(model, kin, j: int, donor: int) -> MassProperties:
    """The frame of joint ``j``: the donor's mass and inertia times :data:`FRAME_MASS_FRACTION`,
    at the donor's centre of mass, in joint ``j``'s frame (``body frame`` of ``make_body``)."""
    j_M_donor = kin.oMi[j].inverse() * kin.oMi[donor]
    inertia = model.inertias[donor].se3Action(j_M_donor)
    share = FRAME_MASS_FRACTION
    return share * float(inertia.mass), np.array(inertia.lever), share * np.array(inertia.inertia)


def donor_keep(donors: dict[int, int]) -> dict[int, float]:
    """Per donor joint, the fraction of its mass and inertia it keeps after feeding its frames."""
    count: dict[int, int] = {}
    for d in donors.values():
        count[d] = count.get(d, 0) + 1
    return {d: 1.0 - FRAME_MASS_FRACTION * n for d, n in count.items()}


def frames_note(model, donors: dict[int, int], links_of: dict[int, list[str]]) -> str:
    """The load note naming the massless links that became joint frames."""
    links = [name for j in donors for name in links_of.get(j, [model.names[j]])]
    return (
        f"links with neither mass nor geometry that carry a joint {links}: each is a joint "
        "frame (an affine body that collides with nothing, carrying "
        f"{FRAME_MASS_FRACTION:g} of the mass and inertia of the first massive link below it, "
        "taken from that link); the joints and their coordinates are the URDF's"
    )
