"""Simulation: Scene (what to simulate, with which settings) and World (the stepper)."""

from abdsim.sim.contact_forces import ContactForces
from abdsim.sim.joints import ActuatorHandle, JointHandle
from abdsim.sim.scene import GROUND, BodyHandle, ContactTable, Ground, Scene
from abdsim.sim.sensors import SensorSet, SensorSpec
from abdsim.sim.settings import SceneSettings
from abdsim.sim.world import (
    SolverError,
    StepDiagnostics,
    World,
    q_to_transforms,
    transforms_to_q,
)

__all__ = [
    "GROUND",
    "ActuatorHandle",
    "BodyHandle",
    "ContactForces",
    "ContactTable",
    "Ground",
    "JointHandle",
    "Scene",
    "SceneSettings",
    "SensorSet",
    "SensorSpec",
    "SolverError",
    "StepDiagnostics",
    "World",
    "q_to_transforms",
    "transforms_to_q",
]
