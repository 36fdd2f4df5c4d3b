#include "solver/constrained_solve.h"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "solver/diagnostics.h"

namespace abd {

// The KKT matrix K = [H Jᵀ; J 0] (soft rows: [H Jᵀ; J −D], D = 1/k) is factorised as the quasi-definite [H Jᵀ; J −εI] (H SPD):
// such a matrix has an LDLᵀ factorisation for every symmetric ordering, so the sparse
// Cholesky machinery applies with its fill-reducing ordering and a tree of joints costs what
// a chain of blocks costs. ε = 1e-12 · max diag(H) shifts the constraint rows by ε·λ, which
// two steps of iterative refinement against the exact K remove (each shrinks the error by
// ~ε·|J H⁻¹ Jᵀ|).
void KktFactorisation::solve(const BlockSystem& system, const std::vector<ConstraintRow>& rows,
                             const VecX& rhs, VecX& x) {
  if (use_tree_ && tree_.solve(system, rows, rhs, x)) return;
  std::vector<int> index;
  const Eigen::SparseMatrix<double> H = system.lower_matrix(index);
  const int n_bodies = static_cast<int>(index.size());
  const Eigen::Index n = H.rows();
  auto free_body = [&](int b) { return b >= 0 && index[b] >= 0; };

  std::vector<const ConstraintRow*> active;
  for (const ConstraintRow& r : rows)
    if (free_body(r.body_a) || free_body(r.body_b)) active.push_back(&r);
  // Soft rows (BlockSystem::soft_rows, both bodies free) follow the hard ones, with their
  // compliance −1/k on the diagonal instead of −ε.
  const auto& soft = system.soft_rows();
  const Eigen::Index m_hard = static_cast<Eigen::Index>(active.size());
  const Eigen::Index m = m_hard + static_cast<Eigen::Index>(soft.size());

  using Triplet = Eigen::Triplet<double>;
  std::vector<Triplet> triplets;
  triplets.reserve(static_cast<std::size_t>(H.nonZeros() + 24 * m + m));
  double scale = 0.0;
  for (int k = 0; k < H.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(H, k); it; ++it) {
      triplets.emplace_back(it.row(), it.col(), it.value());
      if (it.row() == it.col()) scale = std::max(scale, std::abs(it.value()));
    }
  auto add_row = [&](Eigen::Index k, int body_a, const Vec12& ja, int body_b, const Vec12& jb) {
    for (const auto& [body, grad] : {std::pair<int, const Vec12*>{body_a, &ja},
                                     std::pair<int, const Vec12*>{body_b, &jb}}) {
      if (!free_body(body)) continue;
      for (int d = 0; d < 12; ++d)
        if ((*grad)[d] != 0.0) triplets.emplace_back(n + k, 12 * index[body] + d, (*grad)[d]);
    }
  };
  for (Eigen::Index k = 0; k < m_hard; ++k)
    add_row(k, active[k]->body_a, active[k]->ja, active[k]->body_b, active[k]->jb);
  for (Eigen::Index k = m_hard; k < m; ++k) {
    const HessianRow& r = soft[k - m_hard];
    if (!(r.k > 0.0))
      throw SolverError("a Hessian row between bodies " + std::to_string(r.a) + " and " +
                        std::to_string(r.b) + " has a stiffness that is not positive");
    add_row(k, r.a, r.ga, r.b, r.gb);
    triplets.emplace_back(n + k, n + k, -1.0 / r.k);
  }
  // The −εI block enters with the triplets (inserting into a compressed matrix would cost
  // O(nnz) per entry); the exact K is K_reg + ε [0 0; 0 I] on the hard rows.
  const double eps = 1e-12 * (scale > 0.0 ? scale : 1.0);
  for (Eigen::Index k = 0; k < m_hard; ++k) triplets.emplace_back(n + k, n + k, -eps);
  Eigen::SparseMatrix<double> K_reg(n + m, n + m);
  K_reg.setFromTriplets(triplets.begin(), triplets.end());  // lower triangle

  VecX b(n + m);
  for (int body = 0; body < n_bodies; ++body)
    if (index[body] >= 0) b.segment<12>(12 * index[body]) = rhs.segment<12>(12 * body);
  for (Eigen::Index k = 0; k < m_hard; ++k) b[n + k] = -active[k]->value;
  b.tail(m - m_hard).setZero();

  K_reg.makeCompressed();
  const int nnz = static_cast<int>(K_reg.nonZeros());
  const int* outer = K_reg.outerIndexPtr();
  const int* inner = K_reg.innerIndexPtr();
  const bool same = analysed_ && outer_.size() == static_cast<std::size_t>(K_reg.cols() + 1) &&
                    inner_.size() == static_cast<std::size_t>(nnz) &&
                    std::equal(outer_.begin(), outer_.end(), outer) &&
                    std::equal(inner_.begin(), inner_.end(), inner);
  if (!same) {
    ldlt_.analyzePattern(K_reg);
    outer_.assign(outer, outer + K_reg.cols() + 1);
    inner_.assign(inner, inner + nnz);
    analysed_ = true;
  }
  ldlt_.factorize(K_reg);
  auto& ldlt = ldlt_;
  if (ldlt.info() != Eigen::Success)
    throw SolverError("sparse LDLT factorisation of the constrained Newton system failed");
  VecX u = ldlt.solve(b);
  for (int refine = 0; refine < 2 && m_hard > 0; ++refine) {
    VecX residual = b - K_reg.selfadjointView<Eigen::Lower>() * u;
    residual.segment(n, m_hard) -= eps * u.segment(n, m_hard);  // b − K u with the exact K
    u += ldlt.solve(residual);
  }
  // Redundant rows (a loop, a doubled joint) make K singular: λ blows up or goes non-finite.
  if (ldlt.info() != Eigen::Success || !u.allFinite())
    throw SolverError("the constrained Newton direction is not finite (redundant or "
                      "degenerate constraints among " + std::to_string(m) + " rows?)");
  x.setZero(12 * n_bodies);
  for (int body = 0; body < n_bodies; ++body)
    if (index[body] >= 0) x.segment<12>(12 * body) = u.segment<12>(12 * index[body]);
}

}  // namespace abd
