// The Newton step under equality constraints (solver/constraint.h): the KKT system
//   [H Jᵀ; J 0] [x; λ] = [rhs; −c]
// solved as one sparse quasi-definite LDLᵀ (constrained_solve.cpp), H being SPD (the projected
// Newton matrix, or the mass matrix for a projection): a tree of joints costs about what its
// chain of 12x12 blocks costs. The system's soft rows (BlockSystem::soft_rows: rank-one
// Hessian parts k g gᵀ kept out of H) enter as rows with −1/k on the diagonal, the same
// Newton step. Exact (no stiffness), so a step from a point where linear
// constraints hold keeps them to round-off.
#pragma once
#include <Eigen/SparseCholesky>
#include <vector>

#include "solver/block_system.h"
#include "solver/constraint.h"
#include "solver/tree_kkt.h"

namespace abd {

// The factorisation kept between solves: a KKT matrix with the sparsity pattern of the last
// one (an articulation without contact keeps it step after step) skips the fill-reducing
// ordering and symbolic analysis, which cost as much as the numeric factorisation.
class KktFactorisation {
 public:
  // tree = false: always the general sparse path (for tests).
  explicit KktFactorisation(bool tree = true) : use_tree_(tree) {}
  // x over every body (zero on the bodies fixed in `system`). Columns of fixed bodies are
  // dropped from the rows (they are constants this solve); rows with no free column are
  // ignored. Throws SolverError when the system cannot be factorised or solved (redundant
  // constraints, a loop). An articulation without loops (joints and couplings forming a
  // forest) takes the exact block-tree elimination of tree_kkt.h.
  void solve(const BlockSystem& system, const std::vector<ConstraintRow>& rows,
             const VecX& rhs, VecX& x);

 private:
  bool use_tree_ = true;
  TreeKkt tree_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt_;
  std::vector<int> outer_, inner_;  // pattern of the analysed matrix
  bool analysed_ = false;
};

}  // namespace abd
