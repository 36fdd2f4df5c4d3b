#include "solver/block_ldlt.h"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <algorithm>

namespace abd {
namespace {

// Unpivoted LDLᵀ of a 12x12 block in place from its lower triangle: the strict lower
// triangle becomes L's (unit diagonal implied), inv_d = 1 / D. Whole-column updates (the
// rows above a column's diagonal take values that are never read). False on a zero pivot.
bool dense_ldlt(Mat12& A, Vec12& inv_d) {
  for (int j = 0; j < 12; ++j) {
    const double d = A(j, j);
    if (d == 0.0) return false;
    const double inv = 1.0 / d;
    inv_d[j] = inv;
    for (int k = j + 1; k < 12; ++k) A.col(k) -= (A(k, j) * inv) * A.col(j);
    for (int i = j + 1; i < 12; ++i) A(i, j) *= inv;
  }
  return true;
}

// X ← X L⁻ᵀ for a unit lower L (its strict lower triangle).
void solve_right_transposed(const Mat12& L, Mat12& X) {
  for (int c = 0; c < 12; ++c)
    for (int k = c + 1; k < 12; ++k) X.col(k) -= L(k, c) * X.col(c);
}

}  // namespace

void BlockLdlt::analyse(int m, const std::vector<std::pair<int, int>>& pairs) {
  m_ = m;
  // AMD on the bodies' graph (Eigen's AMDOrdering gives P⁻¹: new index → old).
  {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(size_t(m) + 2 * pairs.size());
    for (int k = 0; k < m; ++k) t.emplace_back(k, k, 1.0);
    for (const auto& [a, b] : pairs) {
      t.emplace_back(a, b, 1.0);
      t.emplace_back(b, a, 1.0);
    }
    Eigen::SparseMatrix<double> graph(m, m);
    graph.setFromTriplets(t.begin(), t.end());
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> new_to_old;
    Eigen::AMDOrdering<int> amd;
    amd(graph, new_to_old);
    old_of_new_.assign(new_to_old.indices().data(), new_to_old.indices().data() + m);
  }
  std::vector<int> new_of_old(static_cast<size_t>(m));
  for (int k = 0; k < m; ++k) new_of_old[size_t(old_of_new_[size_t(k)])] = k;

  // The lower blocks of A by column, then the symbolic elimination: column j's pattern is
  // A's plus its children's in the elimination tree (less j itself).
  std::vector<std::vector<int>> pattern(static_cast<size_t>(m)), children(static_cast<size_t>(m));
  for (const auto& [a, b] : pairs) {
    const int i = new_of_old[size_t(a)], j = new_of_old[size_t(b)];
    pattern[size_t(std::min(i, j))].push_back(std::max(i, j));
  }
  col_start_.assign(size_t(m) + 1, 0);
  row_.clear();
  for (int j = 0; j < m; ++j) {
    std::vector<int>& p = pattern[size_t(j)];
    for (int c : children[size_t(j)])
      for (int r = col_start_[size_t(c)]; r < col_start_[size_t(c) + 1]; ++r)
        if (row_[size_t(r)] != j) p.push_back(row_[size_t(r)]);
    std::sort(p.begin(), p.end());
    p.erase(std::unique(p.begin(), p.end()), p.end());
    if (!p.empty()) children[size_t(p[0])].push_back(j);
    row_.insert(row_.end(), p.begin(), p.end());
    col_start_[size_t(j) + 1] = int(row_.size());
  }
  auto slot = [&](int i, int k) {  // the block (i, k), i > k, of L
    const auto first = row_.begin() + col_start_[size_t(k)];
    const auto last = row_.begin() + col_start_[size_t(k) + 1];
    return int(std::lower_bound(first, last, i) - row_.begin());
  };
  pair_slot_.resize(pairs.size());
  pair_transposed_.resize(pairs.size());
  for (size_t p = 0; p < pairs.size(); ++p) {
    const int i = new_of_old[size_t(pairs[p].first)], j = new_of_old[size_t(pairs[p].second)];
    pair_slot_[p] = i > j ? slot(i, j) : slot(j, i);
    pair_transposed_[p] = i < j;
  }
  update_start_.assign(size_t(m) + 1, 0);
  update_slot_.clear();
  for (int j = 0; j < m; ++j) {
    for (int u = col_start_[size_t(j)]; u < col_start_[size_t(j) + 1]; ++u)
      for (int v = u; v < col_start_[size_t(j) + 1]; ++v)
        update_slot_.push_back(v == u ? -1 : slot(row_[size_t(v)], row_[size_t(u)]));
    update_start_[size_t(j) + 1] = int(update_slot_.size());
  }
  diag_.resize(size_t(m));
  inv_d_.resize(size_t(m));
  blocks_.resize(row_.size());
}

bool BlockLdlt::factorize(const std::vector<const Mat12*>& diagonal,
                          const std::vector<const Mat12*>& coupling) {
  for (int k = 0; k < m_; ++k) diag_[size_t(k)] = *diagonal[size_t(old_of_new_[size_t(k)])];
  for (Mat12& B : blocks_) B.setZero();
  for (size_t p = 0; p < coupling.size(); ++p) {
    if (pair_transposed_[p])
      blocks_[size_t(pair_slot_[p])] = coupling[p]->transpose();
    else
      blocks_[size_t(pair_slot_[p])] = *coupling[p];
  }
  for (int j = 0; j < m_; ++j) {
    Mat12& Ljj = diag_[size_t(j)];
    if (!dense_ldlt(Ljj, inv_d_[size_t(j)])) return false;
    const int first = col_start_[size_t(j)], count = col_start_[size_t(j) + 1] - first;
    // W = A'_ij L_jj⁻ᵀ, kept for the updates; L_ij = W D_j⁻¹.
    scratch_.resize(size_t(count));
    for (int u = 0; u < count; ++u) {
      Mat12& W = scratch_[size_t(u)];
      W = blocks_[size_t(first + u)];
      solve_right_transposed(Ljj, W);
      blocks_[size_t(first + u)] = W * inv_d_[size_t(j)].asDiagonal();
    }
    // A'_ik −= L_ij D_j L_kjᵀ = L_ij W_kᵀ for every pair of the column's blocks.
    const int* target = update_slot_.data() + update_start_[size_t(j)];
    for (int u = 0; u < count; ++u)
      for (int v = u; v < count; ++v) {
        const int s = *target++;
        const Mat12& L_v = blocks_[size_t(first + v)];
        if (s < 0)
          diag_[size_t(row_[size_t(first + v)])].noalias() -= L_v * scratch_[size_t(u)].transpose();
        else
          blocks_[size_t(s)].noalias() -= L_v * scratch_[size_t(u)].transpose();
      }
  }
  return true;
}

void BlockLdlt::solve(VecX& x) const {
  VecX& y = solve_scratch_;  // kept: no allocation per solve
  y.resize(12 * m_);
  for (int k = 0; k < m_; ++k) y.segment<12>(12 * k) = x.segment<12>(12 * old_of_new_[size_t(k)]);
  for (int j = 0; j < m_; ++j) {  // L z = P x, column by column
    const Mat12& L = diag_[size_t(j)];
    Vec12 yj = y.segment<12>(12 * j);
    for (int c = 0; c < 11; ++c)
      for (int i = c + 1; i < 12; ++i) yj[i] -= L(i, c) * yj[c];
    y.segment<12>(12 * j) = yj;
    for (int s = col_start_[size_t(j)]; s < col_start_[size_t(j) + 1]; ++s)
      y.segment<12>(12 * row_[size_t(s)]).noalias() -= blocks_[size_t(s)] * yj;
  }
  for (int j = 0; j < m_; ++j) y.segment<12>(12 * j) = y.segment<12>(12 * j).cwiseProduct(inv_d_[size_t(j)]);
  for (int j = m_ - 1; j >= 0; --j) {  // Lᵀ (P x) = D⁻¹ z, row by row from the last
    Vec12 yj = y.segment<12>(12 * j);
    for (int s = col_start_[size_t(j)]; s < col_start_[size_t(j) + 1]; ++s)
      yj.noalias() -= blocks_[size_t(s)].transpose() * y.segment<12>(12 * row_[size_t(s)]);
    const Mat12& L = diag_[size_t(j)];
    for (int c = 10; c >= 0; --c)
      for (int i = c + 1; i < 12; ++i) yj[c] -= L(i, c) * yj[i];
    y.segment<12>(12 * j) = yj;
  }
  for (int k = 0; k < m_; ++k) x.segment<12>(12 * old_of_new_[size_t(k)]) = y.segment<12>(12 * k);
}

}  // namespace abd
