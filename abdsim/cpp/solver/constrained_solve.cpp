#include "solver/constrained_solve.h"

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <string>

#include "solver/diagnostics.h"

namespace abd {

void solve_constrained(const BlockSystem& system, const std::vector<ConstraintRow>& rows,
                       const VecX& rhs, VecX& x) {
  std::vector<int> index;
  const Eigen::SparseMatrix<double> A = system.lower_matrix(index);
  const int n_bodies = static_cast<int>(index.size());
  const Eigen::Index n = A.rows();
  auto free_body = [&](int b) { return b >= 0 && index[b] >= 0; };

  // Jᵀ restricted to the free dofs, one column per row that can move.
  std::vector<const ConstraintRow*> active;
  for (const ConstraintRow& r : rows)
    if (free_body(r.body_a) || free_body(r.body_b)) active.push_back(&r);
  const Eigen::Index m = static_cast<Eigen::Index>(active.size());
  Eigen::MatrixXd Jt = Eigen::MatrixXd::Zero(n, m);
  VecX c(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    const ConstraintRow& r = *active[k];
    if (free_body(r.body_a)) Jt.col(k).segment<12>(12 * index[r.body_a]) += r.ja;
    if (free_body(r.body_b)) Jt.col(k).segment<12>(12 * index[r.body_b]) += r.jb;
    c[k] = r.value;
  }

  VecX b_free(n);
  for (int b = 0; b < n_bodies; ++b)
    if (index[b] >= 0) b_free.segment<12>(12 * index[b]) = rhs.segment<12>(12 * b);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt(A);
  if (ldlt.info() != Eigen::Success)
    throw SolverError("sparse LDLT factorisation of the Newton matrix failed");
  VecX u = ldlt.solve(b_free);
  if (m > 0) {
    const Eigen::MatrixXd Y = ldlt.solve(Jt);
    const Eigen::MatrixXd S = Jt.transpose() * Y;
    const Eigen::LDLT<Eigen::MatrixXd> schur(S);
    const VecX lambda = schur.solve(Jt.transpose() * u + c);
    // A singular Schur complement (redundant rows) would give a non-finite or inconsistent λ.
    const double scale = S.diagonal().cwiseAbs().maxCoeff();
    if (schur.info() != Eigen::Success || !lambda.allFinite() ||
        !(schur.vectorD().cwiseAbs().minCoeff() > 1e-13 * scale))
      throw SolverError("the joint constraints are redundant or degenerate (singular KKT "
                        "system with " + std::to_string(m) + " constraint rows)");
    u -= Y * lambda;
  }
  if (!u.allFinite()) throw SolverError("the constrained Newton direction is not finite");
  x.setZero(12 * n_bodies);
  for (int b = 0; b < n_bodies; ++b)
    if (index[b] >= 0) x.segment<12>(12 * b) = u.segment<12>(12 * index[b]);
}

}  // namespace abd
