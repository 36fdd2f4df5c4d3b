// One evaluator for every smooth piece of every primitive-pair squared distance.
//
// Each piece (point–point, point–line, point–plane, line–line) is the minimum over
// barycentric parameters β of the squared length of an affine combination of the vertices:
//     d²(x) = min_β |r(x, β)|²,   r = Σ_i w_i(β) x_i,   w(β) = c + a β.
// E.g. point–plane: r = p − t0 − β1 (t1 − t0) − β2 (t2 − t0).  Because Σ_i w_i = 0 for every
// stencil, r is translation invariant, so we work relative to x_0 to limit cancellation.
//
// Derivatives follow from the optimality of β (no per-case symbolic algebra):
//   gradient (envelope theorem):      ∂d²/∂x_i = 2 w_i r
//   Hessian (implicit differentiation): H = 2 (w wᵀ ⊗ I₃) − 2 Cᵀ U⁻¹ C,
// with u_k = Σ_i a_ik x_i (∂r/∂β_k), U = [u_k · u_l] and C_k = [a_ik r + w_i u_k]_i (row).
// For NB = 2, det U = |u_1 × u_2|² (Lagrange's identity), which is far more accurate than
// U00 U11 − U01² for near-parallel edges or thin triangles.
#pragma once
#include <array>

#include "common/types.h"

namespace abd::contact {

template <int NV>
struct AffineDistance {
  static constexpr int N = 3 * NV;
  double d2 = 0.0;
  Eigen::Matrix<double, NV, 1> w;   // closest-point weights: r = Σ w_i x_i
  Vec3 r = Vec3::Zero();            // the closest-point difference vector
  Eigen::Matrix<double, N, 1> grad;
  Eigen::Matrix<double, N, N> hess;
  // The Hessian's factors (order 2), for a caller that works in its structure
  // (contact/barrier_projection.h): nb = NB, the first nb columns of a and u, and U⁻¹.
  int nb = 0;
  Eigen::Matrix<double, NV, 2> a;
  Eigen::Matrix<double, 3, 2> u;
  Eigen::Matrix2d U_inv;
};

// order: 0 value (and w, r), 1 + gradient, 2 + the Hessian's factors, and the dense Hessian
// unless dense_hessian = false (a caller that works in the factors alone).
template <int NV, int NB>
AffineDistance<NV> affine_distance(const std::array<Vec3, NV>& x,
                                   const Eigen::Matrix<double, NV, 1>& c,
                                   const Eigen::Matrix<double, NV, NB>& a, int order,
                                   bool dense_hessian = true) {
  AffineDistance<NV> out;
  Eigen::Matrix<double, 3, NV> X;
  for (int i = 0; i < NV; ++i) X.col(i) = x[i] - x[0];

  const Vec3 r0 = X * c;
  Eigen::Matrix<double, 3, NB> u = X * a;
  Eigen::Matrix<double, NB, NB> U_inv;
  Eigen::Matrix<double, NB, 1> beta;
  if constexpr (NB == 1) {
    const double uu = u.col(0).squaredNorm();
    U_inv(0, 0) = 1.0 / uu;
    beta(0) = -u.col(0).dot(r0) / uu;
  } else if constexpr (NB == 2) {
    const double det = u.col(0).cross(u.col(1)).squaredNorm();
    const double u00 = u.col(0).squaredNorm(), u11 = u.col(1).squaredNorm();
    const double u01 = u.col(0).dot(u.col(1));
    U_inv << u11 / det, -u01 / det, -u01 / det, u00 / det;
    const Eigen::Matrix<double, 2, 1> rhs(-u.col(0).dot(r0), -u.col(1).dot(r0));
    beta = U_inv * rhs;
  }
  if constexpr (NB > 0) {
    out.w = c + a * beta;
    out.r = r0 + u * beta;
  } else {
    out.w = c;
    out.r = r0;
  }
  out.d2 = out.r.squaredNorm();
  if (order < 1) return out;

  for (int i = 0; i < NV; ++i) out.grad.template segment<3>(3 * i) = 2.0 * out.w[i] * out.r;
  if (order < 2) return out;

  if (dense_hessian)
    for (int i = 0; i < NV; ++i)
      for (int j = 0; j < NV; ++j)
        out.hess.template block<3, 3>(3 * i, 3 * j) = 2.0 * out.w[i] * out.w[j] * Mat3::Identity();
  if constexpr (NB > 0) {
    if (dense_hessian) {
      Eigen::Matrix<double, NB, 3 * NV> C;
      for (int k = 0; k < NB; ++k)
        for (int i = 0; i < NV; ++i)
          C.template block<1, 3>(k, 3 * i) = (a(i, k) * out.r + out.w[i] * u.col(k)).transpose();
      out.hess -= 2.0 * C.transpose() * U_inv * C;
    }
    out.a.template leftCols<NB>() = a;
    out.u.template leftCols<NB>() = u;
    out.U_inv.template topLeftCorner<NB, NB>() = U_inv;
  }
  out.nb = NB;
  return out;
}

}  // namespace abd::contact
