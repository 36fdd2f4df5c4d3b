// OrthoPotential Ψ = ‖AAᵀ − I‖²_F, derivatives with respect to the rows of A (9 dofs).
#pragma once
#include "common/types.h"

namespace abd {
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;

double ortho_potential(const Mat3& A);
// Ψ, with ws·∇Ψ added to g's last 9 entries (a body's q = [p; rows of A]) and, where given,
// ws·∇²Ψ to H's bottom-right 9x9 block, the Hessian projected to PSD when `project`. The
// projection clamps negative eigenvalues to zero (never a shift: a shift would add stiffness
// to the rotational modes, which only the mass should govern). `absorb` > 0: a lower bound
// on the smallest eigenvalue of H as given (the body's kinetic term); when ws times a bound
// on the negative eigenvalues of ∇²Ψ is within it, the sum is positive definite with the
// exact Hessian and the clamp (an eigen-solve) is skipped: Newton's own matrix there. This
// is the one implementation used by the simulator and by the public energy().
double ortho_potential_add_body_derivatives(const Mat3& A, bool project, double ws, Vec12& g,
                                            Mat12* H, double absorb = 0.0);
}  // namespace abd
