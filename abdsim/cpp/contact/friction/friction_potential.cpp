#include "contact/friction/friction_potential.h"

#include <algorithm>

#include "contact/friction/smooth_friction.h"

namespace abd::contact {

FrictionDerivatives friction_potential(const StencilVec& dx, const StencilWeights& w,
                                       const Mat3x2& T, double mu_lambda, double eps, int order,
                                       bool majorize) {
  const int nv = int(w.size());
  Eigen::Matrix<double, 2, Eigen::Dynamic, 0, 2, kMaxStencilDofs> Gamma(2, 3 * nv);
  for (int i = 0; i < nv; ++i) Gamma.block<2, 3>(0, 3 * i) = w[i] * T.transpose();
  const Eigen::Vector2d u = Gamma * dx;
  const double y = u.norm();

  FrictionDerivatives out;
  out.value = mu_lambda * smooth_friction_f0(y, eps);
  if (order < 1) return out;
  const double f1_over_y = smooth_friction_f1_over_x(y, eps);
  out.grad = mu_lambda * f1_over_y * (Gamma.transpose() * u);
  if (order < 2) return out;

  // M = α I + (λ_u − α) û ûᵀ, with λ_u the (clamped) eigenvalue along u.
  Eigen::Matrix2d M = f1_over_y * Eigen::Matrix2d::Identity();
  if (y > 0.0 && !majorize) {
    const double along = f1_over_y + smooth_friction_f2_x_minus_f1_over_x3(y, eps) * y * y;
    const Eigen::Vector2d uh = u / y;
    M += (std::max(along, 0.0) - f1_over_y) * uh * uh.transpose();
  }
  out.hess = mu_lambda * Gamma.transpose() * M * Gamma;
  return out;
}

}  // namespace abd::contact
