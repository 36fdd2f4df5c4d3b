// Cholesky factorisation and triangular solves on 12x12 matrices (the body blocks and the
// padded rows of a tree node, solver/tree_kkt.h), as plain loops over compile-time sizes:
// Eigen's triangular solves dispatch to its generic dynamic-size kernels, whose set-up costs
// more than the arithmetic at this size. A factor L is lower-triangular and lives in the
// lower triangle of the matrix it was computed in (zeros above), with the unit upper factor
// of Lᵀ in a second matrix (unit_upper); the solves multiply by 1 / diag(L), which the
// factorisation returns (a division in their dependency chain costs several
// multiplications). Every loop updates whole columns
// of fixed length (the zeros of the triangles make that exact): fixed-size column updates
// vectorise, triangular ones of varying length do not, and a dot product per entry is one
// chain of dependent additions.
#pragma once
#include <cmath>

#include "common/types.h"

namespace abd::dense {

// Lᵀ = diag(L) U with U unit upper: U's strict upper triangle, by columns (U(i, j) =
// L(j, i) / L(i, i), zero on and below the diagonal). Back-substitution with U needs no
// multiplication between one entry and the next (upper_solve).
inline void unit_upper(const Mat12& L, const Vec12& inv_diagonal, Mat12& U) {
  U = L.transpose();
  for (int j = 0; j < 12; ++j) {
    U.col(j) = U.col(j).cwiseProduct(inv_diagonal);
    U(j, j) = 0.0;
  }
}

// A = L Lᵀ in place over the leading n x n block, read from its lower triangle (inv_diagonal:
// 1 there, 1 beyond; the block's strict upper triangle is zeroed) and At = unit_upper(L). R: the
// column updates run over the leading R >= n rows only; the rows below the block must be
// zero in its columns (they stay zero). False when a pivot is not positive (or not finite).
//
// The trailing columns are updated with the pivot column before it is scaled, as
// a_k −= (a_kj / d) a_j (d the pivot): the next pivot then waits on one division, not on a
// square root followed by a division (pivot to pivot, that chain is most of the time of a
// 12x12 factorisation). The column's scaling by 1/√d = √d / d is off that path.
template <int R = 12>
bool cholesky(Mat12& A, Mat12& At, Vec12& inv_diagonal, int n = 12) {
  inv_diagonal.setOnes();
  for (int j = 0; j < n; ++j) {
    const double d = A(j, j);
    if (!(d > 0.0) || !std::isfinite(d)) return false;
    const double inv_d = 1.0 / d;
    // Right-looking, on whole columns: rows above the diagonal of a column receive values
    // that are zeroed below.
    for (int k = j + 1; k < n; ++k)
      A.col(k).template head<R>() -= (A(k, j) * inv_d) * A.col(j).template head<R>();
    const double l = std::sqrt(d);
    const double inv = l * inv_d;
    inv_diagonal[j] = inv;
    A.col(j).template head<R>() *= inv;
    A(j, j) = l;
  }
  for (int j = 1; j < n; ++j)
    for (int i = 0; i < j; ++i) A(i, j) = 0.0;
  unit_upper(A, inv_diagonal, At);
  return true;
}

// cholesky<12>(A, At, inv_diagonal) with the forward solves that follow it done in the same
// sweep: t ← L⁻¹ t and W ← W L⁻ᵀ (every row w of W solves L wᵀ = (its value)ᵀ; R: W's rows
// past the leading R are zero and skipped). Each pivot column updates t and W's columns as it
// updates the trailing columns of A (with the unscaled column: the unit-lower factor is
// a_ij / d_j and L = (that) diag(√d)), so their chains run beside the pivots' instead of
// after them. False when a pivot is not positive (or not finite).
template <int R>
bool cholesky_forward(Mat12& A, Mat12& At, Vec12& inv_diagonal, Vec12& t, Mat12& W) {
  Vec12 s = t;  // the unit-lower solve in progress (its rows < j are no longer read)
  for (int j = 0; j < 12; ++j) {
    const double d = A(j, j);
    if (!(d > 0.0) || !std::isfinite(d)) return false;
    const double inv_d = 1.0 / d;
    for (int k = j + 1; k < 12; ++k)
      A.col(k) -= (A(k, j) * inv_d) * A.col(j);
    const double l = std::sqrt(d);
    const double inv = l * inv_d;
    inv_diagonal[j] = inv;
    t[j] = s[j] * inv;
    s -= (s[j] * inv_d) * A.col(j);
    for (int k = j + 1; k < 12; ++k)
      W.col(k).template head<R>() -= (A(k, j) * inv_d) * W.col(j).template head<R>();
    W.col(j).template head<R>() *= inv;
    A.col(j) *= inv;
    A(j, j) = l;
  }
  for (int j = 1; j < 12; ++j)
    for (int i = 0; i < j; ++i) A(i, j) = 0.0;
  unit_upper(A, inv_diagonal, At);
  return true;
}

// v ← L⁻¹ v over the leading n entries (L's leading n x n block, zeros above it). Entry j
// takes the update of column j too and is then set: the column's zeros leave the others.
inline void lower_solve(const Mat12& L, const Vec12& inv_diagonal, Vec12& v, int n = 12) {
  for (int j = 0; j < n; ++j) {
    const double x = v[j] * inv_diagonal[j];
    v.noalias() -= x * L.col(j);
    v[j] = x;
  }
}

// v ← L⁻ᵀ v over the leading n entries, from U = unit_upper(L) (cholesky's At): U v' = v / diag(L).
inline void upper_solve(const Mat12& U, const Vec12& inv_diagonal, Vec12& v, int n = 12) {
  v = v.cwiseProduct(inv_diagonal);  // 1 past n
  for (int j = n - 1; j > 0; --j) v.noalias() -= v[j] * U.col(j);
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
// L wᵀ = (its value)ᵀ, all rows at once, the inner loops running down W's columns. R: W's
// rows past the leading R are zero (padding) and are skipped.
template <int R = 12>
void solve_rows_of(const Mat12& L, const Vec12& inv_diagonal, Mat12& W, int n) {
  for (int j = 0; j < n; ++j) {
    W.col(j).template head<R>() *= inv_diagonal[j];
    for (int i = j + 1; i < n; ++i)
      W.col(i).template head<R>() -= L(i, j) * W.col(j).template head<R>();
  }
}

// Lower triangle of A −= VᵀV.
inline void subtract_gram(const Mat12& V, Mat12& A) {
  for (int j = 0; j < 12; ++j)
    for (int i = j; i < 12; ++i) A(i, j) -= V.col(i).dot(V.col(j));
}

// A += v vᵀ on whole columns (the lower triangle is what the factorisation reads).
template <class V>
void add_outer(Mat12& A, const V& v) {
  for (int j = 0; j < 12; ++j) A.col(j) += v[j] * v;
}

}  // namespace abd::dense
