"""Runs a scene in abdsim and records it as a Trajectory (rigid-body quantities of ABD bodies).

An affine body's rigid view: centre c_w = A c + p, orientation R = polar(A), COM velocity
Ȧ c + ṗ, angular momentum about the COM  L = axial(A S_c Ȧᵀ − Ȧ S_c Aᵀ) with
S_c = S − m c cᵀ, and kinetic energy ½ q̇ᵀ M q̇ (exact for the affine motion).
"""

from __future__ import annotations

import time

import numpy as np

from abdsim.validation.trajectory import Recorder, Trajectory


def polar_rotation(A: np.ndarray) -> np.ndarray:
    """Rotation factor of the polar decomposition of each 3x3 in A (..., 3, 3)."""
    U, _, Vt = np.linalg.svd(A)
    R = U @ Vt
    flip = np.linalg.det(R) < 0
    if np.any(flip):
        U = U.copy()
        U[flip, :, 2] *= -1
        R = U @ Vt
    return R


class AffineRigidView:
    """Vectorised rigid-body quantities of n affine bodies from their dyadic masses."""

    def __init__(self, mass: np.ndarray, mass_x_bar: np.ndarray, S: np.ndarray) -> None:
        self.mass = np.asarray(mass, float)
        self.center = np.asarray(mass_x_bar, float) / self.mass[:, None]
        self.S_c = np.asarray(S, float) - self.mass[:, None, None] * np.einsum(
            "ni,nj->nij", self.center, self.center
        )

    def sample(self, T: np.ndarray, Tdot: np.ndarray, gravity: np.ndarray) -> dict:
        A, p = T[:, :3, :3], T[:, :3, 3]
        Ad, pd = Tdot[:, :3, :3], Tdot[:, :3, 3]
        com = np.einsum("nij,nj->ni", A, self.center) + p
        v_com = np.einsum("nij,nj->ni", Ad, self.center) + pd
        K = A @ self.S_c @ np.swapaxes(Ad, 1, 2)
        L = np.stack(
            [K[:, 1, 2] - K[:, 2, 1], K[:, 2, 0] - K[:, 0, 2], K[:, 0, 1] - K[:, 1, 0]], axis=1
        )
        # ½ q̇ᵀ M q̇ = ½ m|ṗ|² + ṗ·Ȧ(m x̄) + ½ tr(Ȧ S Ȧᵀ); written about the COM:
        kinetic = 0.5 * self.mass * np.sum(v_com * v_com, axis=1) + 0.5 * np.einsum(
            "nij,njk,nik->n", Ad, self.S_c, Ad
        )
        energy = float(np.sum(kinetic) - np.sum(self.mass * (com @ gravity)))
        return {
            "com": com,
            "rotation": polar_rotation(A),
            "linear_momentum": self.mass[:, None] * v_com,
            "angular_momentum": L,
            "energy": energy,
        }


def run_abdsim(
    world,
    names: list[str],
    body_ids: np.ndarray,
    view: AffineRigidView,
    gravity: np.ndarray,
    duration: float,
    dt: float,
    sample_dt: float,
    progress: bool = True,
    on_step=None,
) -> Trajectory:
    """Step ``world`` for ``duration`` and sample the bodies ``body_ids`` every ``sample_dt``.

    ``on_step(world)`` (optional) is called after every step, e.g. to log to MCAP.
    """
    from tqdm.auto import tqdm

    rec = Recorder("abdsim", names)
    n_steps = int(round(duration / dt))
    every = max(1, int(round(sample_dt / dt)))
    newton_iterations = []

    def sample() -> None:
        s = view.sample(world.transforms()[body_ids], world.velocities()[body_ids], gravity)
        dist = getattr(world, "min_contact_distance", lambda: np.nan)()
        rec.add(time=world.time, contact_distance=dist, **s)
        stored.append(stored_energy(world))

    first_contact = None
    stored: list[float] = []  # per sample, see stored_energy
    sample()
    wall = 0.0
    bar = tqdm(total=n_steps, desc="abdsim", unit="step", disable=not progress, leave=False)
    for k in range(1, n_steps + 1):
        t0 = time.perf_counter()
        world.step()
        wall += time.perf_counter() - t0
        diag = world.diagnostics
        newton_iterations.append(int(getattr(diag, "newton_iterations", 0)))
        # every step: a contact shorter than the sampling interval is not missed
        if first_contact is None and getattr(diag, "min_contact_distance", np.inf) < np.inf:
            first_contact = world.time
        if on_step is not None:
            on_step(world)
        if k % every == 0:
            sample()
        bar.update(1)
    bar.close()
    extra = {
        "newton_iterations": np.asarray(newton_iterations),
        "stored_energy": np.asarray(stored),
    }
    if callable(getattr(world, "min_contact_distance", None)):
        extra["first_contact_time"] = float("inf") if first_contact is None else first_contact
    return rec.finish(wall, n_steps, **extra)


def stored_energy(world) -> float:
    """Energy stored in the potentials at the current state (J): every body's shape energy
    κ v̄ Ψ and the contact barrier's κ B (not friction's lagged dissipation potential). The
    mechanical energy a contact may not increase is kinetic + gravity + this."""
    scene = getattr(world, "scene", None)
    if scene is not None and not scene.settings.energies:
        # Without the step-end energies the shape part would read 0 and the energy check
        # would pass a gain it cannot see.
        raise ValueError(
            "stored_energy needs the step-end energies: the scene's SceneSettings.energies "
            "is off (turn it on to validate energy)"
        )
    contact = getattr(world, "contact", None)
    barrier = float(contact.barrier_value(world.q)) if contact is not None else 0.0
    diag = world.diagnostics
    shape = float(diag.energies.get("shape", 0.0)) if diag is not None else 0.0
    return shape + barrier
