// OrthoPotential Ψ = ‖AAᵀ − I‖²_F, derivatives with respect to the rows of A (9 dofs).
#pragma once
#include "common/types.h"

namespace abd {
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;

double ortho_potential(const Mat3& A);
Vec9 ortho_potential_gradient(const Mat3& A);
Mat9 ortho_potential_hessian(const Mat3& A);
}  // namespace abd
