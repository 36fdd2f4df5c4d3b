// Small fixed-size kernels of the per-body Newton solve, written for speed (the free-flight
// fast path spends its time here): the ABD mass matrix applied from the dyadic mass, the
// OrthoPotential value/gradient/Hessian in one pass, and an in-place Cholesky solve.
#pragma once
#include <cmath>

#include "common/types.h"
#include "mass/dyadic_mass.h"

namespace abd {

// M v, with M the 12x12 ABD mass matrix of `dm` (ABD_NOTES §3).
inline Vec12 mass_times(const DyadicMass& dm, const Vec12& v) {
  Vec12 out;
  const Vec3 vp = v.head<3>();
  for (int i = 0; i < 3; ++i) {
    const Vec3 va = v.segment<3>(3 + 3 * i);
    out[i] = dm.m * vp[i] + dm.m_x_bar.dot(va);
    out.segment<3>(3 + 3 * i) = dm.m_x_bar * vp[i] + dm.S * va;
  }
  return out;
}

// ½ vᵀ M v.
inline double mass_quadratic(const DyadicMass& dm, const Vec12& v) {
  return 0.5 * v.dot(mass_times(dm, v));
}

// Solves H x = b for a symmetric positive-definite N x N matrix (upper triangle read;
// H is overwritten by its Cholesky factor U, H = UᵀU). Column access only, so the loops run
// over contiguous memory. Returns false when H is not numerically positive definite.
template <int N>
bool cholesky_solve(Eigen::Matrix<double, N, N>& H, const Eigen::Matrix<double, N, 1>& b,
                    Eigen::Matrix<double, N, 1>& x) {
  for (int j = 0; j < N; ++j) {
    double d = H(j, j);
    for (int k = 0; k < j; ++k) d -= H(k, j) * H(k, j);
    if (!(d > 0.0)) return false;
    d = std::sqrt(d);
    H(j, j) = d;
    const double inv = 1.0 / d;
    for (int i = j + 1; i < N; ++i) {
      double s = H(j, i);
      for (int k = 0; k < j; ++k) s -= H(k, i) * H(k, j);
      H(j, i) = s * inv;
    }
  }
  for (int i = 0; i < N; ++i) {  // Uᵀ y = b
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= H(k, i) * x[k];
    x[i] = s / H(i, i);
  }
  for (int i = N - 1; i >= 0; --i) {  // U x = y
    double s = x[i];
    for (int k = i + 1; k < N; ++k) s -= H(i, k) * x[k];
    x[i] = s / H(i, i);
  }
  return true;
}

}  // namespace abd
