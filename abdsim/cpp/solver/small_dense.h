// Cholesky factorisation and triangular solves on 12x12 matrices (the body blocks and the
// padded rows of a tree node, solver/tree_kkt.h), as plain loops over compile-time sizes:
// Eigen's triangular solves dispatch to its generic dynamic-size kernels, whose set-up costs
// more than the arithmetic at this size. A factor L is lower-triangular and lives in the
// lower triangle of the matrix it was computed in (the strict upper triangle is left as it
// was and never read); the solves multiply by 1 / diag(L), which the factorisation returns
// (a division in their dependency chain costs several multiplications).
#pragma once
#include <cmath>

#include "common/types.h"

namespace abd::dense {

// A = L Lᵀ in place over the leading n x n block (inv_diagonal: 1 there, 1 beyond); false
// when a pivot is not positive (or not finite).
inline bool cholesky(Mat12& A, Vec12& inv_diagonal, int n = 12) {
  inv_diagonal.setOnes();
  for (int j = 0; j < n; ++j) {
    const double d = A(j, j);
    if (!(d > 0.0) || !std::isfinite(d)) return false;
    const double l = std::sqrt(d);
    const double inv = 1.0 / l;
    A(j, j) = l;
    inv_diagonal[j] = inv;
    for (int i = j + 1; i < n; ++i) A(i, j) *= inv;
    for (int k = j + 1; k < n; ++k) {
      const double a = A(k, j);
      for (int i = k; i < n; ++i) A(i, k) -= A(i, j) * a;
    }
  }
  return true;
}

// v ← L⁻¹ v over the leading n entries (L's leading n x n block).
inline void lower_solve(const Mat12& L, const Vec12& inv_diagonal, Vec12& v, int n = 12) {
  for (int j = 0; j < n; ++j) {
    const double x = v[j] * inv_diagonal[j];
    v[j] = x;
    for (int i = j + 1; i < n; ++i) v[i] -= L(i, j) * x;
  }
}

// v ← L⁻ᵀ v over the leading n entries.
inline void upper_solve(const Mat12& L, const Vec12& inv_diagonal, Vec12& v, int n = 12) {
  for (int j = n - 1; j >= 0; --j) {
    double x = v[j];
    for (int i = j + 1; i < n; ++i) x -= L(i, j) * v[i];
    v[j] = x * inv_diagonal[j];
  }
}

// X ← L⁻¹ X, column by column.
inline void lower_solve(const Mat12& L, const Vec12& inv_diagonal, Mat12& X) {
  for (int c = 0; c < 12; ++c) {
    Vec12 x = X.col(c);
    lower_solve(L, inv_diagonal, x);
    X.col(c) = x;
  }
}

// W ← W L⁻ᵀ over W's leading n columns (L's leading n x n block): every row w of W solves
// L wᵀ = (its value)ᵀ, all rows at once, the inner loops running down W's columns.
inline void solve_rows_of(const Mat12& L, const Vec12& inv_diagonal, Mat12& W, int n) {
  for (int j = 0; j < n; ++j) {
    W.col(j) *= inv_diagonal[j];
    for (int i = j + 1; i < n; ++i) W.col(i) -= L(i, j) * W.col(j);
  }
}

// Lower triangle of A −= VᵀV.
inline void subtract_gram(const Mat12& V, Mat12& A) {
  for (int j = 0; j < 12; ++j)
    for (int i = j; i < 12; ++i) A(i, j) -= V.col(i).dot(V.col(j));
}

// Lower triangle of A += v vᵀ.
template <class V>
void add_outer_lower(Mat12& A, const V& v) {
  for (int j = 0; j < 12; ++j) {
    const double a = v[j];
    for (int i = j; i < 12; ++i) A(i, j) += v[i] * a;
  }
}

}  // namespace abd::dense
