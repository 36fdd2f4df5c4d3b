"""Contact forces of the last step, as arrays (``World.contacts`` / ``World.contact_wrenches``).

The forces are those of the contact potentials (IPC barrier and lagged friction) at the state
the step converged to: the step solved M (q − q̃)/c² + ∇Ψ + ∇B + ∇D = 0, so −∇B − ∇D are the
contact forces it applied (N), here per contact pair and summed per body.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ContactForces:
    """The contact pairs of the last step with a non-zero force (k of them).

    Attributes:
        bodies: (k, 2) int: the two bodies of each pair, ``-1`` for the ground. The first is
            the side of the point (point–triangle, point–ground) or of the first edge.
        points: (k, 3): world point between the two closest points (m).
        normals: (k, 3): unit contact normal, from the second body towards the first.
        normal_force: (k,): force along ``normals`` on the first body (N, >= 0; the second
            body gets the opposite).
        friction_force: (k, 3): friction force on the first body (N), tangential; the second
            body gets the opposite. Pairs whose friction was lagged at the step's start but
            that left the barrier's reach during the step have a zero normal force.
        barrier_energy: (k,): the energy the pair's barrier stores (J), part of the bodies'
            mechanical energy (friction's potential is dissipation, not stored: not here).
    """

    bodies: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    normal_force: np.ndarray
    friction_force: np.ndarray
    barrier_energy: np.ndarray

    @classmethod
    def empty(cls) -> ContactForces:
        """No contact."""
        return cls(
            bodies=np.zeros((0, 2), dtype=np.int32),
            points=np.zeros((0, 3)),
            normals=np.zeros((0, 3)),
            normal_force=np.zeros(0),
            friction_force=np.zeros((0, 3)),
            barrier_energy=np.zeros(0),
        )

    @classmethod
    def from_core(cls, d: dict) -> ContactForces:
        """From ``IpcContactTerm.contact_forces``'s dict of arrays."""
        return cls(
            bodies=np.asarray(d["bodies"], dtype=np.int32).reshape(-1, 2),
            points=np.asarray(d["points"], dtype=np.float64).reshape(-1, 3),
            normals=np.asarray(d["normals"], dtype=np.float64).reshape(-1, 3),
            normal_force=np.asarray(d["normal_force"], dtype=np.float64).reshape(-1),
            friction_force=np.asarray(d["friction_force"], dtype=np.float64).reshape(-1, 3),
            barrier_energy=np.asarray(d["barrier_energy"], dtype=np.float64).reshape(-1),
        )

    @property
    def forces(self) -> np.ndarray:
        """(k, 3): total contact force on the first body of each pair (normal + friction)."""
        return self.normal_force[:, None] * self.normals + self.friction_force

    def select(self, mask: np.ndarray) -> ContactForces:
        """The pairs a boolean mask (or index array) over the k pairs picks."""
        return ContactForces(
            bodies=self.bodies[mask],
            points=self.points[mask],
            normals=self.normals[mask],
            normal_force=self.normal_force[mask],
            friction_force=self.friction_force[mask],
            barrier_energy=self.barrier_energy[mask],
        )

    def __len__(self) -> int:
        return len(self.normal_force)


def rest_centers_of_mass(core_scene, handles) -> np.ndarray:
    """(n_bodies, 3): each body's centre of mass in its rest frame (m x̄ / m; 0 if massless).

    One look-up per geometry: the instances of a geometry share their mass properties.
    """
    out = np.zeros((core_scene.num_bodies, 3))
    for h in handles:
        body = core_scene.body(h.start)
        if body.mass > 0:
            out[h.start : h.stop] = np.asarray(body.mass_x_bar) / body.mass
    return out


def world_centers(q: np.ndarray, rest_centers: np.ndarray) -> np.ndarray:
    """(n, 3): x = A c̄ + p of each body's rest centre c̄, for q (n, 12)."""
    A = q[:, 3:].reshape(-1, 3, 3)
    return np.einsum("bij,bj->bi", A, rest_centers) + q[:, :3]
