#include "solver/block_system.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "solver/body_math.h"
#include "solver/diagnostics.h"
#include "solver/parallel.h"

namespace abd {

void BlockSystem::reset(int n_bodies, const std::vector<std::uint8_t>& fixed) {
  n_ = n_bodies;
  fixed_ = fixed;
  diag_.resize(n_);
  offdiag_.clear();
  soft_.clear();
  row_start_.clear();
}

void BlockSystem::add_rows(const std::vector<HessianRow>& rows, bool keep) {
  for (const HessianRow& r : rows) {
    if (r.a < 0 || r.a >= n_ || r.b < -1 || r.b >= n_ || r.a == r.b)
      throw SolverError("an energy term returned a Hessian row for bodies (" +
                        std::to_string(r.a) + ", " + std::to_string(r.b) + ") outside [0, " +
                        std::to_string(n_) + ") or on one body twice");
    const bool free_a = !fixed_[r.a], free_b = r.b >= 0 && !fixed_[r.b];
    if (keep && free_a && free_b) {
      soft_.push_back(r);
      continue;
    }
    if (free_a) diag_[r.a].noalias() += r.k * r.ga * r.ga.transpose();
    if (free_b) diag_[r.b].noalias() += r.k * r.gb * r.gb.transpose();
    if (free_a && free_b) {
      offdiag_.push_back({r.a, r.b, r.k * r.ga * r.gb.transpose()});
      offdiag_.push_back({r.b, r.a, r.k * r.gb * r.ga.transpose()});
    }
  }
}

void BlockSystem::add_blocks(const std::vector<BodyBlock>& blocks) {
  for (const BodyBlock& b : blocks) {
    if (b.row < 0 || b.row >= n_ || b.col < 0 || b.col >= n_)
      throw SolverError("an energy term returned a Hessian block for body (" +
                        std::to_string(b.row) + ", " + std::to_string(b.col) +
                        ") outside [0, " + std::to_string(n_) + ")");
    if (b.row == b.col) {
      if (!fixed_[b.row]) diag_[b.row] += b.H;
    } else if (!fixed_[b.row] && !fixed_[b.col]) {
      offdiag_.push_back({b.row, b.col, b.H});
    }
  }
}

void BlockSystem::finalize() {
  // Sorted by (row, col) and, among equal ones, in the terms' order (a stable sort: the
  // summation order of duplicates is the terms'). The sort runs on keys; each 1.2 kB block
  // is then copied once into its place (sorting the blocks themselves moved each ~log n
  // times: a heap of 100 boxes has ~600 per Newton iteration).
  sort_keys_.resize(offdiag_.size());
  for (std::size_t i = 0; i < offdiag_.size(); ++i)
    sort_keys_[i] = {(static_cast<std::uint64_t>(offdiag_[i].row) << 32) |
                         static_cast<std::uint32_t>(offdiag_[i].col),
                     i};
  std::sort(sort_keys_.begin(), sort_keys_.end());
  // Sum duplicates in that order.
  sorted_.clear();
  for (const auto& [key, i] : sort_keys_) {
    const OffDiagonal& o = offdiag_[i];
    if (!sorted_.empty() && sorted_.back().row == o.row && sorted_.back().col == o.col)
      sorted_.back().H += o.H;
    else
      sorted_.push_back(o);
  }
  offdiag_.swap(sorted_);
  row_start_.assign(n_ + 1, 0);
  for (const OffDiagonal& o : offdiag_) ++row_start_[o.row + 1];
  for (int r = 0; r < n_; ++r) row_start_[r + 1] += row_start_[r];
  // Every coupling (i, j) must come with (j, i) = (i, j)ᵀ.
  for (const OffDiagonal& o : offdiag_) {
    const auto first = offdiag_.begin() + row_start_[o.col];
    const auto last = offdiag_.begin() + row_start_[o.col + 1];
    const auto it = std::lower_bound(first, last, o.row,
                                     [](const OffDiagonal& a, int c) { return a.col < c; });
    const double scale = o.H.cwiseAbs().maxCoeff();
    const bool ok = it != last && it->col == o.row &&
                    (it->H.transpose() - o.H).cwiseAbs().maxCoeff() <= 1e-9 * scale + 1e-300;
    if (!ok)
      throw SolverError("the Hessian is not symmetric: block (" + std::to_string(o.row) + ", " +
                        std::to_string(o.col) +
                        ") has no matching transposed block; an energy term must add every "
                        "coupling block (i, j) together with (j, i) = (i, j)ᵀ");
  }
}

int BlockSystem::solve_block_diagonal(const VecX& rhs, VecX& x, int threads) const {
  std::vector<int> failed(n_, 0);
  parallel_for(n_, threads, [&](int b) {
    if (fixed_[b]) {
      x.segment<12>(12 * b).setZero();
      return;
    }
    Mat12 H = diag_[b];
    Vec12 xb;
    if (!cholesky_solve<12>(H, Vec12(rhs.segment<12>(12 * b)), xb)) {
      failed[b] = 1;
      xb.setZero();
    }
    x.segment<12>(12 * b) = xb;
  });
  for (int b = 0; b < n_; ++b)
    if (failed[b]) return b;
  return -1;
}

template <class F>
void BlockSystem::for_each_lower_entry(const std::vector<int>& index, F&& f) const {
  for (int b = 0; b < n_; ++b) {
    if (fixed_[b]) continue;
    const int i = index[b];
    for (int c = 0; c < 12; ++c)
      for (int r = c; r < 12; ++r) f(12 * i + r, 12 * i + c, diag_[b](r, c));
  }
  // SimplicialLDLT reads the lower triangle: the blocks with row > col, whole (zeros
  // included, so that the pattern depends only on which bodies are coupled).
  for (const OffDiagonal& o : offdiag_) {
    if (o.row < o.col) continue;
    const int i = index[o.row], j = index[o.col];
    for (int c = 0; c < 12; ++c)
      for (int r = 0; r < 12; ++r) f(12 * i + r, 12 * j + c, o.H(r, c));
  }
}

int BlockSystem::free_index(std::vector<int>& index) const {
  // Only the free bodies enter the factorisation (a scene of many bodies may couple a few).
  index.assign(n_, -1);
  int m = 0;
  for (int b = 0; b < n_; ++b)
    if (!fixed_[b]) index[b] = m++;
  return m;
}

Eigen::SparseMatrix<double> BlockSystem::lower_matrix(std::vector<int>& index) const {
  const int m = free_index(index);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(m) * 78 + offdiag_.size() * 144 / 2);
  for_each_lower_entry(index, [&](int r, int c, double v) { triplets.emplace_back(r, c, v); });
  Eigen::SparseMatrix<double> A(12 * m, 12 * m);
  A.setFromTriplets(triplets.begin(), triplets.end());
  return A;
}

bool BlockSystem::solve_direct(const VecX& rhs, VecX& x) {
  const int m = free_index(index_);
  pattern_scratch_.assign(index_.begin(), index_.end());
  for (const OffDiagonal& o : offdiag_)
    if (o.row > o.col) {
      pattern_scratch_.push_back(o.row);
      pattern_scratch_.push_back(o.col);
    }
  const bool analyse = !analysed_ || pattern_scratch_ != pattern_;
  if (analyse) {
    analysed_ = false;
    std::vector<std::pair<int, int>> pairs;
    for (const OffDiagonal& o : offdiag_)
      if (o.row > o.col) pairs.emplace_back(index_[o.row], index_[o.col]);
    ldlt_.analyse(m, pairs);
    pattern_.swap(pattern_scratch_);
    analysed_ = true;
  }
  diagonal_blocks_.clear();
  for (int b = 0; b < n_; ++b)
    if (!fixed_[b]) diagonal_blocks_.push_back(&diag_[b]);
  coupling_blocks_.clear();
  for (const OffDiagonal& o : offdiag_)
    if (o.row > o.col) coupling_blocks_.push_back(&o.H);
  if (!ldlt_.factorize(diagonal_blocks_, coupling_blocks_))
    throw SolverError("sparse LDLT factorisation of the Newton matrix failed");
  x_free_.resize(12 * m);
  for (int b = 0; b < n_; ++b)
    if (!fixed_[b]) x_free_.segment<12>(12 * index_[b]) = rhs.segment<12>(12 * b);
  ldlt_.solve(x_free_);
  if (!x_free_.allFinite())
    throw SolverError("sparse LDLT solve of the Newton system failed (singular matrix?)");
  x.setZero(12 * n_);
  for (int b = 0; b < n_; ++b)
    if (!fixed_[b]) x.segment<12>(12 * b) = x_free_.segment<12>(12 * index_[b]);
  return analyse;
}

void BlockSystem::multiply(const VecX& v, VecX& out, int threads) const {
  parallel_for(n_, threads, [&](int r) {
    if (fixed_[r]) {
      out.segment<12>(12 * r) = v.segment<12>(12 * r);
      return;
    }
    Vec12 y = diag_[r] * v.segment<12>(12 * r);
    for (int k = row_start_[r]; k < row_start_[r + 1]; ++k)
      y.noalias() += offdiag_[k].H * v.segment<12>(12 * offdiag_[k].col);
    out.segment<12>(12 * r) = y;
  });
}

int BlockSystem::solve_pcg(const VecX& rhs, VecX& x, double tolerance, int max_iterations,
                           int threads) const {
  const int n = 12 * n_;
  std::vector<Eigen::LLT<Mat12>> precond(n_);
  std::vector<int> failed(n_, 0);
  parallel_for(n_, threads, [&](int b) {
    if (fixed_[b]) return;
    precond[b].compute(diag_[b]);
    if (precond[b].info() != Eigen::Success) failed[b] = 1;
  });
  for (int b = 0; b < n_; ++b)
    if (failed[b])
      throw SolverError("PCG: the diagonal block of body " + std::to_string(b) +
                        " is not positive definite");
  auto apply_precond = [&](const VecX& r, VecX& z) {
    parallel_for(n_, threads, [&](int b) {
      if (fixed_[b])
        z.segment<12>(12 * b) = r.segment<12>(12 * b);
      else
        z.segment<12>(12 * b) = precond[b].solve(r.segment<12>(12 * b));
    });
  };
  auto dot = [&](const VecX& a, const VecX& b) {
    return deterministic_sum(n_, threads,
                             [&](int i) { return a.segment<12>(12 * i).dot(b.segment<12>(12 * i)); });
  };
  x.setZero(n);
  VecX r = rhs, z(n), p(n), Ap(n);
  const double rhs_norm = std::sqrt(dot(rhs, rhs));
  if (rhs_norm == 0.0) return 0;
  apply_precond(r, z);
  p = z;
  double rz = dot(r, z);
  for (int it = 1; it <= max_iterations; ++it) {
    multiply(p, Ap, threads);
    const double pAp = dot(p, Ap);
    if (!(pAp > 0.0))
      throw SolverError("PCG: the Newton matrix is not positive definite (pᵀAp = " +
                        std::to_string(pAp) + ")");
    const double alpha = rz / pAp;
    x += alpha * p;
    r -= alpha * Ap;
    if (std::sqrt(dot(r, r)) <= tolerance * rhs_norm) return it;
    apply_precond(r, z);
    const double rz_new = dot(r, z);
    p = z + (rz_new / rz) * p;
    rz = rz_new;
  }
  throw SolverError("PCG did not reach the relative residual " + std::to_string(tolerance) +
                    " in " + std::to_string(max_iterations) + " iterations");
}

}  // namespace abd
