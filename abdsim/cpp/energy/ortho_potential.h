// OrthoPotential Ψ = ‖AAᵀ − I‖²_F, derivatives with respect to the rows of A (9 dofs).
#pragma once
#include "common/types.h"

namespace abd {
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;

double ortho_potential(const Mat3& A);
Vec9 ortho_potential_gradient(const Mat3& A);
// The exact Hessian (not projected).
Mat9 ortho_potential_hessian(const Mat3& A);

// Ψ, and, where given, ws·∇Ψ added to *g and ws·∇²Ψ added to *H, the Hessian projected to
// PSD when `project`. The projection clamps negative eigenvalues to zero (never a shift: a
// shift would add stiffness to the rotational modes, which only the mass should govern).
// This is the one implementation used by the simulator and by the public energy().
double ortho_potential_derivatives(const Mat3& A, bool project, double ws, Vec9* g, Mat9* H);

// The PSD projection of ∇²Ψ(A), from its closed-form eigen-system (see the .cpp).
Mat9 ortho_potential_hessian_psd(const Mat3& A);
}  // namespace abd
