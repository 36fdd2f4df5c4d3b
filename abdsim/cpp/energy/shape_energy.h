// Shape-preservation energies of an affine body (ABD_NOTES §6):
//   uid 1 OrthoPotential  E = κ v̄ ‖AAᵀ − I‖²_F
//   uid 2 ARAP            E = κ v̄ ‖A − R‖²_F   (R the rotation of the polar decomposition)
// Both depend only on A; gradient and Hessian are returned in the 12-dof layout of q
// (zero rows/columns for p), A flattened row-major as in q.
#pragma once
#include "common/types.h"

namespace abd {

enum ConstitutionUid : int { kOrthoPotential = 1, kARAP = 2 };

struct ShapeEnergyResult {
  double value = 0.0;
  Vec12 gradient = Vec12::Zero();
  Mat12 hessian = Mat12::Zero();
};

// Throws std::invalid_argument for an unknown uid. `project_psd` clamps the Hessian's
// negative eigenvalues (analytically for ARAP, numerically for OrthoPotential). `absorb`:
// what the simulator passes for a body (ShapeEnergyTerm::add_body_derivatives): the
// OrthoPotential's clamp is skipped when κ v̄ times a bound on its negative eigenvalues is
// within it (ortho_potential_add_body_derivatives).
ShapeEnergyResult shape_energy(int uid, const Vec12& q, double kappa, double volume,
                               bool project_psd, bool want_hessian = true, double absorb = 0.0);

double shape_energy_value(int uid, const Vec12& q, double kappa, double volume);

}  // namespace abd
