// Cholesky factorisation and triangular solves on 12x12 matrices (the body blocks and the
// padded rows of a tree node, solver/tree_kkt.h), as plain loops over compile-time sizes:
// Eigen's triangular solves dispatch to its generic dynamic-size kernels, whose set-up costs
// more than the arithmetic at this size. A factor L is lower-triangular and lives in the
// lower triangle of the matrix it was computed in (zeros above), with the unit upper factor
// of Lᵀ in a second matrix (cholesky_forward's At); the solves multiply by 1 / diag(L), which the
// factorisation returns (a division in their dependency chain costs several
// multiplications). Every loop updates whole columns
// of fixed length (the zeros of the triangles make that exact): fixed-size column updates
// vectorise, triangular ones of varying length do not, and a dot product per entry is one
// chain of dependent additions.
#pragma once
#include <cmath>
#include <type_traits>

#include "common/types.h"

namespace abd::dense {

// Kernels the compiler must inline. Left to itself, GCC 12 with LTO for an AMD Zen 3 kept
// axpy_below out of line, called with Eigen Block objects built on the stack: each of the
// 78 column updates of a 12x12 factorisation paid a call and that set-up, and the KKT
// solve was half of a Panda step's CPU time. The unrolled factorisation's callers are
// flattened (ABD_DENSE_FLATTEN) so that Eigen's operators inside are inlined too.
#if defined(__GNUC__)
#define ABD_DENSE_INLINE inline __attribute__((always_inline))
#define ABD_DENSE_LAMBDA_INLINE __attribute__((always_inline))
#define ABD_DENSE_FLATTEN __attribute__((flatten))
#else
#define ABD_DENSE_INLINE inline
#define ABD_DENSE_LAMBDA_INLINE
#define ABD_DENSE_FLATTEN
#endif

// f(std::integral_constant<int, J>()) for J = First..Last−1, in order, each call with its
// index as a compile-time constant.
template <int First, int Last, class F>
ABD_DENSE_INLINE void static_for(F&& f) {
  if constexpr (First < Last) {
    f(std::integral_constant<int, First>());
    static_for<First + 1, Last>(f);
  }
}

// Fixed-length views of N contiguous doubles (a Mat12 column is 12 of them).
template <int N>
using ColumnMap = Eigen::Map<Eigen::Matrix<double, N, 1>>;
template <int N>
using ConstColumnMap = Eigen::Map<const Eigen::Matrix<double, N, 1>>;

// y[i] −= f x[i] for i < N.
template <int N>
ABD_DENSE_INLINE void axpy(double* y, double f, const double* x) {
  ColumnMap<N>(y) -= f * ConstColumnMap<N>(x);
}

// y −= f x on rows first..R−1 of two columns of R rows (R = 12: on the fewest whole packets
// that cover them, 8 + 4, 8 from row 4 or the last 4; smaller R: all R rows). Rows above
// `first` may change too: cholesky_forward only reads what lies below the diagonal.
template <int R>
ABD_DENSE_INLINE void axpy_below(double* y, double f, const double* x, int first) {
  if constexpr (R == 12) {
    if (first >= 8) {
      axpy<4>(y + 8, f, x + 8);
    } else if (first >= 4) {
      axpy<8>(y + 4, f, x + 4);
    } else {
      axpy<8>(y, f, x);
      axpy<4>(y + 8, f, x + 8);
    }
  } else {
    axpy<R>(y, f, x);
  }
}

// A = L Lᵀ in place over the leading n x n block, read from its lower triangle (inv_diagonal:
// 1 there, 1 beyond; the block's strict upper triangle is zeroed) and At = the unit upper
// factor U of Lᵀ = diag(L) U (U(i, j) = L(j, i) / L(i, i), zero on and below the diagonal:
// back-substitution with it needs no multiplication between one entry and the next,
// upper_solve; only the block's strict upper triangle is written, the rest of At must be
// zero already), with the forward solves that follow a factorisation done in the same sweep: t ← L⁻¹ t and
// W ← W L⁻ᵀ over W's leading n columns (every row w of W solves L wᵀ = (its value)ᵀ). R: A's
// column updates (and t's) run over the leading R >= n rows only, the rows below the block
// must be zero in its columns (they stay zero), and t's entries past R are left; RW: W's rows
// past the leading RW are zero and skipped. False when a pivot is not positive (or not
// finite).
//
// Each pivot column updates the trailing columns of A before it is scaled, as
// a_k −= (a_kj / d) a_j (d the pivot): the next pivot then waits on one division, not on a
// square root followed by a division (pivot to pivot, that chain is most of the time of a
// 12x12 factorisation); the column's scaling by 1/√d = √d / d is off that path. t and W take
// the same unscaled column (the unit-lower factor is a_ij / d_j, L = (that) diag(√d)), so
// their chains run beside the pivots' instead of after them.
//
// keep_L = false: A is left with L's diagonal only (its columns unscaled, the upper triangle
// not zeroed), for a caller that solves with At and inv_diagonal alone.
//
// N > 0: n = N at compile time (the body blocks: N = 12), so that every loop has a constant
// trip count and is unrolled whole, and axpy_below's choice of packets is made at compile
// time (loop control and those branches were a third of the factorisation's instructions).
template <int R, int RW, int N = 0>
ABD_DENSE_INLINE bool cholesky_forward(Mat12& A, Mat12& At, Vec12& inv_diagonal, Vec12& t,
                                       Mat12& W, int n = 12, bool keep_L = true) {
  if constexpr (N > 0) n = N;
  inv_diagonal.setOnes();
  Vec12 s = t;  // the unit-lower solve in progress (its rows < j are no longer read)
  double* a = A.data();  // column-major: column k at a + 12 k
  double* w = W.data();
  // Pivot j; false when it is not positive (or not finite).
  auto pivot = [&](int j) ABD_DENSE_LAMBDA_INLINE {
    const double* a_j = a + 12 * j;
    const double d = a_j[j];
    if (!(d > 0.0) || !std::isfinite(d)) return false;
    const double inv_d = 1.0 / d;
    // Right-looking, on whole columns: rows above the diagonal of a column receive values
    // that are zeroed below.
    // f = a_kj / d is the unit-lower factor's entry (k, j), which is U(j, k): At's row j.
    for (int k = j + 1; k < n; ++k) {
      const double f = a_j[k] * inv_d;
      At(j, k) = f;
      axpy_below<R>(a + 12 * k, f, a_j, k);  // column k's rows >= k
    }
    const double l = std::sqrt(d);
    const double inv = l * inv_d;
    inv_diagonal[j] = inv;
    t[j] = s[j] * inv;
    axpy_below<R>(s.data(), s[j] * inv_d, a_j, j + 1);
    const double* w_j = w + 12 * j;
    for (int k = j + 1; k < n; ++k) axpy<RW>(w + 12 * k, At(j, k), w_j);
    ColumnMap<RW>(w + 12 * j) *= inv;
    if (keep_L) ColumnMap<R>(a + 12 * j) *= inv;
    A(j, j) = l;
    return true;
  };
  bool ok = true;
  if constexpr (N > 0) {
    static_for<0, N>([&](auto j) ABD_DENSE_LAMBDA_INLINE { ok = ok && pivot(j); });
  } else {
    for (int j = 0; j < n && ok; ++j) ok = pivot(j);
  }
  if (!ok) return false;
  if (keep_L)
    for (int j = 1; j < n; ++j)
      for (int i = 0; i < j; ++i) A(i, j) = 0.0;
  return true;
}

// v ← L⁻¹ v over the leading n entries (L's leading n x n block, zeros above it). Entry j
// takes the update of column j too and is then set: the column's zeros leave the others.
ABD_DENSE_INLINE void lower_solve(const Mat12& L, const Vec12& inv_diagonal, Vec12& v,
                                  int n = 12) {
  for (int j = 0; j < n; ++j) {
    const double x = v[j] * inv_diagonal[j];
    v.noalias() -= x * L.col(j);
    v[j] = x;
  }
}

// v ← L⁻ᵀ v over the leading n entries, from U (cholesky_forward's At): U v' = v / diag(L).
ABD_DENSE_INLINE void upper_solve(const Mat12& U, const Vec12& inv_diagonal, Vec12& v,
                                  int n = 12) {
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

// Lower triangle of A −= VᵀV.
ABD_DENSE_INLINE void subtract_gram(const Mat12& V, Mat12& A) {
  for (int j = 0; j < 12; ++j)
    for (int i = j; i < 12; ++i) A(i, j) -= V.col(i).dot(V.col(j));
}

// The lower triangle of A += X Xᵀ over X's leading n columns (what the factorisation reads;
// above the diagonal A takes part of the sum or none). Column by column with the sum in
// registers: one load and one store of A's column instead of one per rank-one term, on the
// rows from the diagonal down in whole packets (axpy_below's 12, 8 from row 4, last 4).
ABD_DENSE_INLINE void add_gram(Mat12& A, const Mat12& X, int n) {
  auto columns = [&](auto first, int from, int to) {
    constexpr int kRows = 12 - decltype(first)::value;
    for (int j = from; j < to; ++j) {
      Eigen::Matrix<double, kRows, 1> column = A.col(j).template tail<kRows>();
      for (int k = 0; k < n; ++k) column += X(j, k) * X.col(k).template tail<kRows>();
      A.col(j).template tail<kRows>() = column;
    }
  };
  columns(std::integral_constant<int, 0>(), 0, 4);
  columns(std::integral_constant<int, 4>(), 4, 8);
  columns(std::integral_constant<int, 8>(), 8, 12);
}

}  // namespace abd::dense
