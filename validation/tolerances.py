"""Pass/fail thresholds of ``abdsim validate``: documented defaults, overridable by a file."""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, fields
from pathlib import Path


@dataclass(frozen=True)
class Tolerances:
    """Thresholds; a check fails when its measured value exceeds (or, for minima, falls below).

    Free flight is compared up to the first contact of any body in the MuJoCo run.
    """

    #: relative error of mass, centre and inertia against MuJoCo's compiled model
    inertia_rel: float = 1e-9
    #: max centre-of-mass distance to MuJoCo RK4 during free flight [m]
    free_flight_position: float = 1e-4
    #: max orientation angle to MuJoCo RK4 during free flight [rad]
    free_flight_orientation: float = 5e-3
    #: max centre-of-mass distance to the Pinocchio RK4 reference during free flight [m]
    pinocchio_position: float = 1e-4
    #: max relative drift of each body's angular momentum during free flight
    angular_momentum_drift: float = 1e-3
    #: max relative drift of the total energy during free flight
    energy_drift: float = 1e-3
    #: max difference of each body's final centre-of-mass height to MuJoCo's [m], checked
    #: for bodies that are at rest at the end in both simulators
    rest_height: float = 5e-3
    #: speed below which a body counts as at rest [m/s]
    rest_speed: float = 0.05
    #: max difference between abdsim's and MuJoCo's first-contact times [s] (abdsim's
    #: contact starts when a gap falls below d̂, MuJoCo's at zero distance)
    first_contact_time: float = 0.03
    #: max rise of abdsim's total energy (kinetic + gravity + stored in the shape and barrier
    #: potentials) between consecutive samples, relative to its largest magnitude, over the
    #: whole run (contact must not add energy; dissipation is allowed)
    energy_gain: float = 1e-3
    #: smallest admissible abdsim contact distance [m] (abdsim is intersection-free: > 0)
    min_contact_distance: float = 0.0
    #: max joint-coordinate difference to MuJoCo RK4 for jointed scenes [rad or m]
    joint_position: float = 1e-3
    #: max joint violation in abdsim (anchor separation [m], axis misalignment [rad])
    joint_violation: float = 1e-6
    #: max joint-velocity difference to MuJoCo RK4 / Pinocchio for robots [rad/s or m/s]
    joint_velocity: float = 1e-2
    #: max distance of a robot link's joint origin to Pinocchio's [m] (the joints issue's
    #: 2 mm over 0.5 s for the UR5 and the Panda)
    link_position: float = 2e-3
    #: max difference of a dropped robot's base height to MuJoCo's at the end [m]
    base_height: float = 1e-2
    #: max difference of a dropped robot's final joint positions to MuJoCo's [rad or m] (the
    #: feet settle under different friction laws: IPC's smoothed Coulomb, MuJoCo's soft cone)
    stance: float = 5e-2

    @classmethod
    def names(cls) -> list[str]:
        return [f.name for f in fields(cls)]

    @classmethod
    def from_file(cls, path: str | Path) -> Tolerances:
        """Read a JSON (or TOML) file of overrides; unknown keys are an error."""
        path = Path(path)
        if not path.is_file():
            raise FileNotFoundError(f"tolerance file not found: {path}")
        text = path.read_text()
        if path.suffix == ".toml":
            import tomllib

            data = tomllib.loads(text)
        else:
            try:
                data = json.loads(text)
            except json.JSONDecodeError as err:
                raise ValueError(f"tolerance file {path} is not valid JSON: {err}") from err
        if not isinstance(data, dict):
            raise ValueError(f"tolerance file {path} must hold an object of name: value")
        unknown = sorted(set(data) - set(cls.names()))
        if unknown:
            raise ValueError(
                f"unknown tolerance key(s) {unknown} in {path}; valid keys: {cls.names()}"
            )
        values = {}
        for key, value in data.items():
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                raise ValueError(f"tolerance {key!r} must be a number, got {value!r}")
            values[key] = float(value)
        return cls(**values)

    #: time step the accuracy tolerances above are stated for [s]
    REFERENCE_DT = 1e-3
    #: tolerances on the integration error, which shrinks with the step as h^order
    ACCURACY = (
        "free_flight_position",
        "free_flight_orientation",
        "pinocchio_position",
        "angular_momentum_drift",
        "energy_drift",
        "joint_position",
        "joint_velocity",
        "link_position",
    )

    def at_step(self, dt: float, integrator: str = "bdf2") -> Tolerances:
        """These tolerances for a run at time step ``dt``: the integration-error ones are
        stated at h = 1e-3 s and grow as (h / 1e-3)^p above it (p = 2 for BDF2, 1 for
        BDF1: the methods' orders), so a sweep at h = 0.01 asks the accuracy BDF2 can give
        there; every other tolerance (contact, energy gain, inertia) is unchanged, and
        nothing is loosened at h <= 1e-3."""
        ratio = dt / self.REFERENCE_DT
        if not ratio > 1.0:
            return self
        factor = ratio ** (2 if integrator == "bdf2" else 1)
        values = self.as_dict()
        for name in self.ACCURACY:
            values[name] *= factor
        return Tolerances(**values)

    def as_dict(self) -> dict[str, float]:
        return asdict(self)
