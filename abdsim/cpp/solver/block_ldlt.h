// Sparse LDLᵀ of a symmetric matrix made of 12x12 blocks over a graph of bodies (the Newton
// matrix of coupled bodies), by block elimination in a fill-reducing (AMD) order of the
// bodies: every operation is a dense 12x12 kernel (the scalar simplicial LDLᵀ it replaces
// spent most of its time on index arithmetic, 11% of a 100-box heap's Newton iteration).
// The factorisation is the scalar LDLᵀ of the block-permuted matrix (L unit lower
// triangular, D diagonal, no pivoting): like it, it accepts any matrix without a zero pivot,
// definite or not.
#pragma once
#include <utility>
#include <vector>

#include "common/types.h"

namespace abd {

class BlockLdlt {
 public:
  // The pattern: m bodies and the coupled pairs (a, b), a != b, each pair once.
  void analyse(int m, const std::vector<std::pair<int, int>>& pairs);
  // diagonal[k]: body k's block (its lower triangle is read); coupling[p]: the block
  // A(a_p, b_p) of pair p (rows of a_p, columns of b_p), in analyse()'s order. False on a
  // zero pivot.
  bool factorize(const std::vector<const Mat12*>& diagonal,
                 const std::vector<const Mat12*>& coupling);
  // x ← A⁻¹ x (12 m entries, bodies in their own order).
  void solve(VecX& x) const;

 private:
  int m_ = 0;
  std::vector<int> old_of_new_;           // body eliminated k-th
  std::vector<int> col_start_, row_;      // L's blocks below the diagonal, by column (CSC)
  std::vector<int> pair_slot_;            // pair p → its block of L
  std::vector<unsigned char> pair_transposed_;  // the block holds A(a_p, b_p)ᵀ
  // Elimination of column j updates, for each pair u ≤ v of its blocks, the block at
  // (row_[v], row_[u]): update_slot_ lists those targets column by column (−1: diagonal).
  std::vector<int> update_start_, update_slot_;
  std::vector<Mat12> diag_;               // unit lower factor of each diagonal block
  std::vector<Vec12> inv_d_;              // 1 / D
  std::vector<Mat12> blocks_;             // L's off-diagonal blocks
  mutable std::vector<Mat12> scratch_;    // one column's blocks before scaling by D⁻¹
  mutable VecX solve_scratch_;            // solve()'s vector in the elimination order
};

}  // namespace abd
