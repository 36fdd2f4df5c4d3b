#include "contact/barrier_projection.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace abd::contact {

bool project_barrier_hessian(const StencilGeometry& g, double c2, double c1, StencilMat& out) {
  using Vec4 = Eigen::Vector4d;
  // Fixed 5x5 (the eigen-solver's fixed-size code is much faster than its dynamic one):
  // with nb < 2 the unused rows and columns are zero, their eigenvalues 0, dropped below.
  using Small = Eigen::Matrix<double, 5, 5>;
  if (g.nb < 0 || g.w.size() != 4) return false;
  const int nb = g.nb;
  const Vec4 w = g.w;
  const double w_norm = w.norm(), rho = g.r.norm();
  if (!(w_norm > 0.0) || !(rho > 0.0) || !std::isfinite(w_norm) || !std::isfinite(rho))
    return false;
  const Vec4 w_hat = w / w_norm;
  const Vec3 r_hat = g.r / rho;

  // ã_k = a_k − (ŵ·a_k) ŵ, orthonormalised (Gram–Schmidt, twice): ã_k = Σ_l q̃_l T(l, k).
  Eigen::Matrix<double, 4, 2> q_tilde;
  Eigen::Matrix2d T = Eigen::Matrix2d::Zero();
  for (int k = 0; k < nb; ++k) {
    Vec4 v = g.a.col(k) - w_hat.dot(g.a.col(k)) * w_hat;
    const double scale = g.a.col(k).norm();
    for (int pass = 0; pass < 2; ++pass)
      for (int l = 0; l < k; ++l) {
        const double h = q_tilde.col(l).dot(v);
        T(l, k) += h;
        v -= h * q_tilde.col(l);
      }
    const double norm = v.norm();
    // a_k and w are independent for every piece; a tiny remainder means a broken input
    if (!(norm > 1e-8 * scale)) return false;
    T(k, k) = norm;
    q_tilde.col(k) = v / norm;
  }

  // H = B M Bᵀ with B = [w ⊗ e_i, C_kᵀ] = Q R, M = diag(4 c2 r rᵀ + 2 c1 I₃, −2 c1 U⁻¹).
  Small R = Small::Zero(), M = Small::Zero();
  R.topLeftCorner<3, 3>().diagonal().setConstant(w_norm);
  for (int k = 0; k < nb; ++k) {
    R.block<3, 1>(0, 3 + k) = w_hat.dot(g.a.col(k)) * g.r + w_norm * g.u.col(k);
    for (int l = 0; l <= k; ++l) R(3 + l, 3 + k) = rho * T(l, k);
  }
  M.topLeftCorner<3, 3>() = 4.0 * c2 * g.r * g.r.transpose();
  M.topLeftCorner<3, 3>().diagonal().array() += 2.0 * c1;
  if (nb > 0) M.block(3, 3, nb, nb) = -2.0 * c1 * g.U_inv.topLeftCorner(nb, nb);
  Small S = R * M * R.transpose();
  S = 0.5 * (S + S.transpose());

  Eigen::SelfAdjointEigenSolver<Small> eig(S);
  if (eig.info() != Eigen::Success) return false;
  // Q V √λ₊ column by column: Q's columns are ŵ ⊗ e_i and q̃_l ⊗ r̂.
  Eigen::Matrix<double, 12, 5> Y;
  int kept = 0;
  for (int j = 0; j < 5; ++j) {
    const double lambda = eig.eigenvalues()[j];
    if (!(lambda > 0.0)) continue;
    const auto v = eig.eigenvectors().col(j);
    Vec3 top = v.head<3>();
    Vec4 side = Vec4::Zero();
    for (int l = 0; l < nb; ++l) side += v[3 + l] * q_tilde.col(l);
    const double s = std::sqrt(lambda);
    for (int i = 0; i < 4; ++i)
      Y.block<3, 1>(3 * i, kept) = s * (w_hat[i] * top + side[i] * r_hat);
    ++kept;
  }
  out.setZero(12, 12);
  if (kept > 0) out.noalias() = Y.leftCols(kept) * Y.leftCols(kept).transpose();
  return true;
}

}  // namespace abd::contact
