"""A simulator-neutral record of a run: per-body centre of mass, orientation, momenta, energy.

Every simulator in the harness (abdsim, MuJoCo, Pinocchio) fills one of these at the same
sample times, so the comparison code never needs to know where the numbers came from.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Trajectory:
    """Samples of a run. ``n`` bodies, ``T`` samples.

    Attributes:
        simulator: ``"abdsim"``, ``"mujoco"`` or ``"pinocchio"``.
        names: body names, in the order of the arrays' body axis.
        time: (T,) sample times [s].
        com: (T, n, 3) world centre of mass [m].
        rotation: (T, n, 3, 3) world orientation of each body frame.
        linear_momentum: (T, n, 3) [kg m/s].
        angular_momentum: (T, n, 3) about each body's centre of mass, world frame [kg m²/s].
        energy: (T,) kinetic + gravitational potential energy of all bodies [J].
        contact_distance: (T,) signed minimum contact distance (negative = penetration), NaN
            when nothing is in contact range.
        wall_time: seconds spent stepping (setup excluded).
        steps: number of simulator steps taken.
    """

    simulator: str
    names: list[str]
    time: np.ndarray
    com: np.ndarray
    rotation: np.ndarray
    linear_momentum: np.ndarray
    angular_momentum: np.ndarray
    energy: np.ndarray
    contact_distance: np.ndarray
    wall_time: float = 0.0
    steps: int = 0
    extra: dict = field(default_factory=dict)

    def first_contact_time(self, threshold: float = 0.0) -> float:
        """Time of the first contact: from the simulator's every step when it recorded it
        (``extra["first_contact_time"]``: a short contact between two samples is not missed),
        else the first sample whose contact distance is <= ``threshold`` (inf if never)."""
        if "first_contact_time" in self.extra:
            return float(self.extra["first_contact_time"])
        hit = np.nonzero(np.nan_to_num(self.contact_distance, nan=np.inf) <= threshold)[0]
        return float(self.time[hit[0]]) if len(hit) else float("inf")


class Recorder:
    """Accumulates samples into a Trajectory."""

    def __init__(self, simulator: str, names: list[str]) -> None:
        self.simulator = simulator
        self.names = list(names)
        self._rows: dict[str, list] = {
            k: []
            for k in (
                "time",
                "com",
                "rotation",
                "linear_momentum",
                "angular_momentum",
                "energy",
                "contact_distance",
            )
        }

    def add(self, **sample: object) -> None:
        for key, rows in self._rows.items():
            rows.append(np.asarray(sample[key], dtype=np.float64))

    def add_rigid(
        self, time: float, state: dict, gravity: np.ndarray, contact_distance: float = np.nan
    ) -> None:
        """Add a sample from rigid-body state (com, rotation, v_com, omega, momenta, mass)."""
        energy = rigid_energy(
            state["mass"],
            state["v_com"],
            state["omega"],
            state["angular_momentum"],
            state["com"],
            gravity,
        )
        self.add(
            time=time,
            com=state["com"],
            rotation=state["rotation"],
            linear_momentum=state["linear_momentum"],
            angular_momentum=state["angular_momentum"],
            energy=energy,
            contact_distance=contact_distance,
        )

    def finish(self, wall_time: float, steps: int, **extra: object) -> Trajectory:
        data = {k: np.stack(v) if v else np.zeros(0) for k, v in self._rows.items()}
        return Trajectory(
            self.simulator, self.names, wall_time=wall_time, steps=steps, extra=dict(extra), **data
        )


def skew(w: np.ndarray) -> np.ndarray:
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def rotation_angle(Ra: np.ndarray, Rb: np.ndarray) -> np.ndarray:
    """Angle of Ra Rbᵀ (broadcast over leading axes), robust near 0 and π."""
    rel = Ra @ np.swapaxes(Rb, -1, -2)
    c = np.clip((np.trace(rel, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    s = 0.5 * np.linalg.norm(
        np.stack(
            [
                rel[..., 2, 1] - rel[..., 1, 2],
                rel[..., 0, 2] - rel[..., 2, 0],
                rel[..., 1, 0] - rel[..., 0, 1],
            ],
            axis=-1,
        ),
        axis=-1,
    )
    return np.arctan2(s, c)


def rigid_energy(
    mass: np.ndarray,
    v_com: np.ndarray,
    omega: np.ndarray,
    L: np.ndarray,
    com: np.ndarray,
    gravity: np.ndarray,
) -> float:
    """Σ ½ m |v|² + ½ ω·L − m g·c over bodies (arrays with a leading body axis)."""
    kinetic = 0.5 * np.sum(mass * np.sum(v_com * v_com, axis=1)) + 0.5 * np.sum(omega * L)
    return float(kinetic - np.sum(mass * (com @ gravity)))
