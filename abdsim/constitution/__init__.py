"""Constitutions (shape energies + dyadic mass) and rigid-body conversions."""

from abdsim.constitution.affine_body import (
    CONSTITUTION_UIDS,
    AffineBodyConstitution,
    AffineBodyRod,
    AffineBodyShell,
    ShapeEnergy,
)
from abdsim.constitution.rigid_body import (
    DyadicMass,
    RigidBody,
    assign_rigid_body,
    check_inertia,
    from_rigid_body,
    mass_matrix,
    to_rigid_body,
)

__all__ = [
    "CONSTITUTION_UIDS",
    "AffineBodyConstitution",
    "AffineBodyRod",
    "AffineBodyShell",
    "DyadicMass",
    "RigidBody",
    "ShapeEnergy",
    "assign_rigid_body",
    "check_inertia",
    "from_rigid_body",
    "mass_matrix",
    "to_rigid_body",
]
