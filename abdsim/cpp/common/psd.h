// Projection of a symmetric matrix onto the PSD cone (clamp negative eigenvalues), used by
// every energy Hessian so that Newton directions are descent directions.
#pragma once
#include <Eigen/Eigenvalues>

namespace abd {

template <typename Derived>
typename Derived::PlainObject project_psd(const Eigen::MatrixBase<Derived>& H) {
  using M = typename Derived::PlainObject;
  const M sym = 0.5 * (H + H.transpose());
  Eigen::SelfAdjointEigenSolver<M> eig(sym);
  auto lambda = eig.eigenvalues();
  bool all_positive = true;
  for (Eigen::Index i = 0; i < lambda.size(); ++i) {
    if (lambda[i] < 0.0) {
      lambda[i] = 0.0;
      all_positive = false;
    }
  }
  if (all_positive) return sym;
  return eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace abd
