#include "solver/tree_kkt.h"

#include <algorithm>

namespace abd {
namespace {

// A pivot of S = J H⁻¹ Jᵀ below this fraction of its largest diagonal says the node's rows
// are (nearly) dependent: the general path decides what that means.
constexpr double kPivotFloor = 1e-13;

int find(std::vector<int>& uf, int a) {
  while (uf[a] != a) {
    uf[a] = uf[uf[a]];
    a = uf[a];
  }
  return a;
}

}  // namespace

bool TreeKkt::build_forest(const BlockSystem& system, const std::vector<ConstraintRow>& rows) {
  const int n = system.num_bodies();
  auto free_body = [&](int b) { return b >= 0 && !system.is_fixed(b); };
  edges_.clear();
  unary_.assign(n, 0);
  for (const ConstraintRow& r : rows) {
    const bool fa = free_body(r.body_a), fb = free_body(r.body_b);
    if (fa && fb && r.body_a != r.body_b)
      edges_.emplace_back(std::min(r.body_a, r.body_b), std::max(r.body_a, r.body_b));
    else if (fa != fb)
      unary_[fa ? r.body_a : r.body_b] = 1;
  }
  for (const BlockSystem::OffDiagonal& o : system.couplings())
    if (o.row > o.col) edges_.emplace_back(o.col, o.row);
  std::sort(edges_.begin(), edges_.end());
  edges_.erase(std::unique(edges_.begin(), edges_.end()), edges_.end());

  uf_.resize(n);
  for (int b = 0; b < n; ++b) uf_[b] = b;
  for (const auto& [a, b] : edges_) {
    const int ra = find(uf_, a), rb = find(uf_, b);
    if (ra == rb) return false;  // a loop
    uf_[std::max(ra, rb)] = std::min(ra, rb);
  }
  adjacency_start_.assign(n + 1, 0);
  for (const auto& [a, b] : edges_) {
    ++adjacency_start_[a + 1];
    ++adjacency_start_[b + 1];
  }
  for (int b = 0; b < n; ++b) adjacency_start_[b + 1] += adjacency_start_[b];
  adjacency_.resize(adjacency_start_[n]);
  std::vector<int> fill(adjacency_start_.begin(), adjacency_start_.end() - 1);
  for (const auto& [a, b] : edges_) {  // edges are sorted: neighbours come out ascending
    adjacency_[fill[a]++] = b;
    adjacency_[fill[b]++] = a;
  }
  for (int b = 0; b < n; ++b)
    std::sort(adjacency_.begin() + adjacency_start_[b], adjacency_.begin() + adjacency_start_[b + 1]);

  // Each tree hangs from the body held against the world (its rows then stay on their own
  // node), else from its smallest index.
  std::vector<int> root(n, -1);
  for (int b = 0; b < n; ++b) {
    if (!free_body(b)) continue;
    int& r = root[find(uf_, b)];
    if (r < 0 || (!unary_[r] && unary_[b])) r = b;
  }
  nodes_.resize(n);
  for (Node& node : nodes_) node.parent = -2;  // unvisited
  order_.clear();
  for (int b = 0; b < n; ++b) {
    if (!free_body(b) || root[find(uf_, b)] != b) continue;
    nodes_[b].parent = -1;
    std::size_t head = order_.size();
    order_.push_back(b);
    while (head < order_.size()) {
      const int u = order_[head++];
      for (int k = adjacency_start_[u]; k < adjacency_start_[u + 1]; ++k) {
        const int v = adjacency_[k];
        if (nodes_[v].parent != -2 || v == nodes_[u].parent) continue;
        nodes_[v].parent = u;
        order_.push_back(v);
      }
    }
  }
  return true;
}

void TreeKkt::solve_node(const Node& node, const Vec12& rhs, const Values& c, Vec12& x,
                         Values& lambda) const {
  // H x + Jᵀ λ = rhs, J x = −c: λ = S⁻¹ (J H⁻¹ rhs + c), x = H⁻¹ (rhs − Jᵀ λ).
  x = node.llt.solve(rhs);
  if (node.J.rows() == 0) return;
  lambda = node.S.solve(node.J * x + c);
  x -= node.llt.solve(node.J.transpose() * lambda);
}

bool TreeKkt::factor_node(int b) {
  Node& node = nodes_[b];
  node.llt.compute(node.H);
  if (node.llt.info() != Eigen::Success) return false;
  const Eigen::Index m = node.J.rows();
  Cols12 U;  // L⁻¹ Jᵀ
  if (m > 0) {
    U = node.J.transpose();
    node.llt.matrixL().solveInPlace(U);
    Square S;
    S.noalias() = U.transpose() * U;
    node.S.compute(S);
    if (node.S.info() != Eigen::Success) return false;
    const auto L = node.S.matrixLLT().diagonal();
    if (!(L.minCoeff() * L.minCoeff() > kPivotFloor * L.maxCoeff() * L.maxCoeff())) return false;
  }
  solve_node(node, node.r, node.c, node.yx, node.yl);
  if (node.parent < 0) return true;
  Node& parent = nodes_[node.parent];
  Rows12 Q = -node.JP;  // J H⁻¹ H_bP − J_P, then L_S⁻¹ of it
  if (node.coupling) {
    Mat12 V = *node.coupling;
    node.llt.matrixL().solveInPlace(V);
    if (m > 0) Q.noalias() += U.transpose() * V;
    parent.H.noalias() -= V.transpose() * V;
    parent.r.noalias() -= node.coupling->transpose() * node.yx;
  }
  if (m > 0) {
    node.S.matrixL().solveInPlace(Q);
    parent.H.noalias() += Q.transpose() * Q;
    parent.r.noalias() -= node.JP.transpose() * node.yl;
  }
  return true;
}

bool TreeKkt::solve(const BlockSystem& system, const std::vector<ConstraintRow>& rows,
                    const VecX& rhs, VecX& x) {
  if (!build_forest(system, rows)) return false;
  const int n = system.num_bodies();
  auto free_body = [&](int b) { return b >= 0 && !system.is_fixed(b); };

  // Each row goes to the node that is the child end of its edge (or its one free body).
  auto owner = [&](const ConstraintRow& r) {
    const bool fa = free_body(r.body_a), fb = free_body(r.body_b);
    if (fa && fb) return nodes_[r.body_a].parent == r.body_b ? r.body_a : r.body_b;
    return fa ? r.body_a : fb ? r.body_b : -1;
  };
  row_start_.assign(n + 1, 0);
  for (const ConstraintRow& r : rows) {
    const int o = owner(r);
    if (o >= 0) ++row_start_[o + 1];
  }
  for (int b = 0; b < n; ++b) row_start_[b + 1] += row_start_[b];
  row_list_.resize(row_start_[n]);
  std::vector<int> fill(row_start_.begin(), row_start_.end() - 1);
  for (int k = 0; k < static_cast<int>(rows.size()); ++k) {
    const int o = owner(rows[k]);
    if (o >= 0) row_list_[fill[o]++] = k;
  }

  const auto& couplings = system.couplings();
  for (const int b : order_) {
    Node& node = nodes_[b];
    const int m = row_start_[b + 1] - row_start_[b];
    if (m > 12) return false;
    node.H = system.diagonal(b);
    node.r = rhs.segment<12>(12 * b);
    node.J.resize(m, 12);
    node.JP.setZero(m, 12);
    node.c.resize(m);
    for (int k = 0; k < m; ++k) {
      const ConstraintRow& r = rows[row_list_[row_start_[b] + k]];
      const bool own_a = r.body_a == b;
      node.J.row(k) = (own_a ? r.ja : r.jb).transpose();
      const int other = own_a ? r.body_b : r.body_a;
      if (node.parent >= 0 && other == node.parent)
        node.JP.row(k) = (own_a ? r.jb : r.ja).transpose();
      node.c[k] = r.value;
    }
    node.coupling = nullptr;
    if (node.parent >= 0) {
      const auto it = std::lower_bound(
          couplings.begin(), couplings.end(), std::make_pair(b, node.parent),
          [](const BlockSystem::OffDiagonal& o, const std::pair<int, int>& key) {
            return o.row != key.first ? o.row < key.first : o.col < key.second;
          });
      if (it != couplings.end() && it->row == b && it->col == node.parent) node.coupling = &it->H;
    }
  }
  for (auto it = order_.rbegin(); it != order_.rend(); ++it)
    if (!factor_node(*it)) return false;

  x.setZero(12 * n);
  Vec12 w;
  Values t;
  for (const int b : order_) {
    const Node& node = nodes_[b];
    if (node.parent < 0) {
      x.segment<12>(12 * b) = node.yx;
      continue;
    }
    // u_b = y_b − K_b⁻¹ C_b x_P, C_b x_P = [H_bP x_P; J_P x_P].
    const Vec12 xp = x.segment<12>(12 * node.parent);
    const Vec12 a = node.coupling ? Vec12(*node.coupling * xp) : Vec12::Zero();
    const Values jp = node.JP * xp;
    solve_node(node, a, Values(-jp), w, t);
    x.segment<12>(12 * b) = node.yx - w;
  }
  return x.allFinite();
}

}  // namespace abd
