"""abdsim: Affine Body Dynamics for robotics.

Every body carries 12 DOF ``q = [p, a1, a2, a3]``; a material point moves as ``x = A x̄ + p``.
Quick tour::

    import abdsim
    sc = abdsim.geometry.box((0.2, 0.1, 0.05))
    abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8, mass_density=1e3)
    print(abdsim.to_rigid_body(sc))

    scene = abdsim.Scene(dt=0.01)
    handle = scene.add(sc)
    world = abdsim.World(scene)
    world.step(100)
    print(world.transforms())
"""

from abdsim import geometry
from abdsim.constitution import (
    AffineBodyConstitution,
    AffineBodyRod,
    AffineBodyShell,
    DyadicMass,
    RigidBody,
    assign_rigid_body,
    from_rigid_body,
    mass_matrix,
    to_rigid_body,
)
from abdsim.geometry import SimplicialComplex
from abdsim.sim import (
    GROUND,
    ActuatorHandle,
    BodyHandle,
    ContactTable,
    JointHandle,
    Scene,
    SceneSettings,
    SolverError,
    StepDiagnostics,
    World,
)

__version__ = "0.1.0"

__all__ = [
    "GROUND",
    "ActuatorHandle",
    "AffineBodyConstitution",
    "AffineBodyRod",
    "AffineBodyShell",
    "BodyHandle",
    "ContactTable",
    "DyadicMass",
    "JointHandle",
    "RigidBody",
    "Scene",
    "SceneSettings",
    "SimplicialComplex",
    "SolverError",
    "StepDiagnostics",
    "World",
    "assign_rigid_body",
    "from_rigid_body",
    "geometry",
    "mass_matrix",
    "to_rigid_body",
]
