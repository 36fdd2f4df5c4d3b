"""Print the mass properties abdsim derives for a few affine bodies.

Run: python examples/mass_properties.py
"""

import numpy as np
import trimesh

import abdsim


def show(name: str, sc: abdsim.SimplicialComplex) -> None:
    rb = abdsim.to_rigid_body(sc)
    np.set_printoptions(precision=6, suppress=True)
    print(f"{name}")
    print(
        f"  constitution_uid {int(sc.meta['constitution_uid'])}, volume {sc.meta['volume']:.6g} m^3"
    )
    print(f"  mass {rb.mass:.6g} kg, centre {rb.mass_center}")
    print("  inertia about centre [kg m^2]")
    print("    " + np.array2string(rb.inertia, prefix="    "))
    eig = np.linalg.eigvalsh(abdsim.mass_matrix(sc))
    print(f"  12x12 mass matrix eigenvalues in [{eig.min():.3g}, {eig.max():.3g}] (SPD)\n")


box = abdsim.geometry.box((0.4, 0.2, 0.1))
abdsim.AffineBodyConstitution("OrthoPotential").apply_to(box, kappa=1e8, mass_density=1000.0)
show("solid box 0.4 x 0.2 x 0.1 m (OrthoPotential)", box)

torus = abdsim.geometry.from_trimesh(trimesh.creation.torus(0.3, 0.05))
abdsim.AffineBodyConstitution("ARAP").apply_to(torus, kappa=1e9, mass_density=7800.0)
show("steel torus (ARAP)", torus)

sheet = abdsim.geometry.triangle_mesh(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]]
)
abdsim.AffineBodyShell().apply_to(sheet, kappa=1e8, mass_density=2700.0, thickness=0.001)
show("aluminium sheet 1 x 1 m, 2 mm (shell)", sheet)

rod = abdsim.geometry.edge_mesh([[0, 0, 0], [0, 0, 1]], [[0, 1]])
abdsim.AffineBodyRod().apply_to(rod, kappa=1e8, mass_density=1000.0, thickness=0.01)
show("rod 1 m, radius 1 cm", rod)
