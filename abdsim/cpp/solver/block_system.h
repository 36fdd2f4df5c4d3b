// The Newton system H Δq = -g in 12x12 body blocks, and its three solvers: per-body
// Cholesky when no block couples two bodies, a sparse block LDLᵀ (block_ldlt.h), and PCG
// with a 12x12 block-Jacobi preconditioner.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/SparseCore>

#include "solver/block_ldlt.h"
#include "solver/energy_term.h"

namespace abd {

class BlockSystem {
 public:
  // A coupling block between two free bodies: rows of `row`, columns of `col`.
  struct OffDiagonal {
    int row;
    int col;
    Mat12 H;
  };

  // `fixed[b]` marks bodies whose dofs are prescribed: identity rows, zero right-hand side.
  void reset(int n_bodies, const std::vector<std::uint8_t>& fixed);

  Mat12& diagonal(int b) { return diag_[b]; }
  const Mat12& diagonal(int b) const { return diag_[b]; }
  // Adds term blocks: diagonal ones to the body blocks, couplings between two free bodies
  // to the off-diagonal set (summed per (row, col)). Blocks touching a fixed body only
  // contribute their diagonal part.
  void add_blocks(const std::vector<BodyBlock>& blocks);
  // Adds rank-one rows (HessianRow). keep = false: as their blocks (what add_blocks would
  // get). keep = true: rows between two free bodies stay rows (soft_rows(), for the KKT
  // solves, which eliminate them like constraint rows); their part on one free body goes
  // to its diagonal block. Before finalize().
  void add_rows(const std::vector<HessianRow>& rows, bool keep);
  // Call once all blocks are in: sorts the couplings into rows, sums duplicates and checks
  // that every coupling comes with its transpose (throws SolverError otherwise).
  void finalize();
  bool coupled() const { return !offdiag_.empty() || !soft_.empty(); }
  // Rows kept by add_rows(rows, true), each between two free bodies.
  const std::vector<HessianRow>& soft_rows() const { return soft_; }
  // After finalize(): the couplings, each (i, j) with its (j, i), sorted by (row, col).
  const std::vector<OffDiagonal>& couplings() const { return offdiag_; }
  int num_bodies() const { return n_; }
  bool is_fixed(int b) const { return fixed_[b] != 0; }
  // The lower triangle of the matrix over the free bodies (what SimplicialLDLT reads);
  // index[b] = the position of body b among them (−1 for fixed bodies).
  Eigen::SparseMatrix<double> lower_matrix(std::vector<int>& index) const;

  // Per-body solve, valid when !coupled(). Returns the first body whose block is not
  // positive definite, or -1.
  int solve_block_diagonal(const VecX& rhs, VecX& x, int threads) const;
  // Sparse block LDLᵀ of the assembled matrix. Throws SolverError on failure. The sparsity
  // pattern, its fill-reducing ordering and symbolic factorisation are kept from the last
  // call while the free bodies and the coupled pairs stay the same (then only the values
  // are written and factorised again); returns true when a new symbolic analysis ran.
  bool solve_direct(const VecX& rhs, VecX& x);
  // Returns the iteration count; throws SolverError when it does not converge.
  int solve_pcg(const VecX& rhs, VecX& x, double tolerance, int max_iterations,
                int threads) const;

 private:
  void multiply(const VecX& v, VecX& out, int threads) const;
  // Calls f(row, col, value) for every stored lower-triangle entry of the free bodies'
  // matrix, always in the same order for the same pattern.
  template <class F>
  void for_each_lower_entry(const std::vector<int>& index, F&& f) const;
  // index[b]: body b's block among the free bodies (-1 if fixed); returns their count.
  int free_index(std::vector<int>& index) const;

  int n_ = 0;
  std::vector<std::uint8_t> fixed_;
  std::vector<Mat12> diag_;
  std::vector<OffDiagonal> offdiag_;
  // finalize()'s scratch: (row, col) keys with the blocks' positions, and the sorted blocks.
  std::vector<std::pair<std::uint64_t, std::size_t>> sort_keys_;
  std::vector<OffDiagonal> sorted_;
  std::vector<HessianRow> soft_;
  std::vector<int> row_start_;  // CSR over offdiag_ after finalize()

  // solve_direct's cache: the pattern it was analysed for (free bodies' indices, then the
  // (row, col) of the lower coupling blocks) and its block LDLᵀ (ordering and symbolic
  // factorisation kept, values factorised again on each call).
  std::vector<int> index_;
  std::vector<int> pattern_;
  std::vector<int> pattern_scratch_;
  BlockLdlt ldlt_;
  std::vector<const Mat12*> diagonal_blocks_, coupling_blocks_;
  VecX x_free_;  // the free bodies' right-hand side, then their solution
  bool analysed_ = false;
};

}  // namespace abd
