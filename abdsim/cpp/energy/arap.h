// ARAP Ψ = ‖A − R‖²_F with A = RS (polar), derivatives with respect to the rows of A.
// The Hessian uses the analytic eigen-system of Kim & Eberle ("Dynamic Deformables"):
// 2 on the six stretch modes, 2 − 4/(σ_i + σ_j) on the three twist modes.
#pragma once
#include "energy/ortho_potential.h"

namespace abd {
double arap(const Mat3& A);
Vec9 arap_gradient(const Mat3& A);
Mat9 arap_hessian(const Mat3& A, bool project_psd);
}  // namespace abd
