#include "energy/arap.h"

#include <Eigen/SVD>
#include <cmath>

namespace abd {
namespace {

struct SignedSVD {
  Mat3 U, V;
  Vec3 sigma;
};

// SVD with U, V proper rotations; the sign of an inversion goes into the last singular
// value, so that R = UVᵀ is the rotation of the polar decomposition.
SignedSVD signed_svd(const Mat3& A) {
  Eigen::JacobiSVD<Mat3> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  SignedSVD s{svd.matrixU(), svd.matrixV(), svd.singularValues()};
  if (s.U.determinant() < 0.0) {
    s.U.col(2) *= -1.0;
    s.sigma[2] *= -1.0;
  }
  if (s.V.determinant() < 0.0) {
    s.V.col(2) *= -1.0;
    s.sigma[2] *= -1.0;
  }
  return s;
}

Vec9 flatten_rows(const Mat3& M) {
  Vec9 v;
  for (int i = 0; i < 3; ++i) v.segment<3>(3 * i) = M.row(i).transpose();
  return v;
}

}  // namespace

double arap(const Mat3& A) {
  const SignedSVD s = signed_svd(A);
  return (A - s.U * s.V.transpose()).squaredNorm();
}

Vec9 arap_gradient(const Mat3& A) {
  const SignedSVD s = signed_svd(A);
  return flatten_rows(2.0 * (A - s.U * s.V.transpose()));
}

Mat9 arap_hessian(const Mat3& A, bool project_psd) {
  const SignedSVD s = signed_svd(A);
  // ∂²Ψ/∂A² = 2 I − 2 ∂R/∂A. ∂R/∂A is rank 3: on the twist T_k = U Q_k Vᵀ/√2 (Q_k the
  // skew generator of the axis pair (i, j)) it has eigenvalue 2/(σ_i + σ_j).
  Mat9 H = 2.0 * Mat9::Identity();
  const int pairs[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  for (const auto& pr : pairs) {
    const int i = pr[0], j = pr[1];
    Mat3 Q = Mat3::Zero();
    Q(i, j) = -1.0;
    Q(j, i) = 1.0;
    const Vec9 t = flatten_rows(s.U * Q * s.V.transpose() / std::sqrt(2.0));
    double denom = s.sigma[i] + s.sigma[j];
    // The twist eigenvalue is singular at σ_i + σ_j = 0 (a fully flattened pair); keep it
    // finite there.
    if (std::abs(denom) < 1e-12) denom = denom < 0.0 ? -1e-12 : 1e-12;
    double lambda = 2.0 - 4.0 / denom;
    if (project_psd && lambda < 0.0) lambda = 0.0;
    H += (lambda - 2.0) * t * t.transpose();
  }
  return H;
}

}  // namespace abd
