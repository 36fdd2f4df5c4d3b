#include "solver/tree_kkt.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "common/finite.h"
#include "solver/small_dense.h"

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

void TreeKkt::signature(const BlockSystem& system, const std::vector<ConstraintRow>& rows,
                        std::vector<int>& out) const {
  const int n = system.num_bodies();
  out.clear();
  out.push_back(n);
  for (int b = 0; b < n; ++b) out.push_back(system.is_fixed(b));
  for (const ConstraintRow& r : rows) {
    out.push_back(r.body_a);
    out.push_back(r.body_b);
  }
  out.push_back(-2);
  for (const HessianRow& r : system.soft_rows()) {
    out.push_back(r.a);
    out.push_back(r.b);
  }
  out.push_back(-2);
  for (const BlockSystem::OffDiagonal& o : system.couplings()) {
    out.push_back(o.row);
    out.push_back(o.col);
  }
}

bool TreeKkt::build_forest(const BlockSystem& system, const std::vector<ConstraintRow>& rows) {
  const int n = system.num_bodies();
  auto free_body = [&](int b) { return b >= 0 && !system.is_fixed(b); };
  const auto& soft = system.soft_rows();
  edges_.clear();
  unary_.assign(n, 0);
  for (const ConstraintRow& r : rows) {
    const bool fa = free_body(r.body_a), fb = free_body(r.body_b);
    if (fa && fb && r.body_a != r.body_b)
      edges_.emplace_back(std::min(r.body_a, r.body_b), std::max(r.body_a, r.body_b));
    else if (fa != fb)
      unary_[fa ? r.body_a : r.body_b] = 1;
  }
  for (const HessianRow& r : soft) edges_.emplace_back(std::min(r.a, r.b), std::max(r.a, r.b));
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
  fill_.assign(adjacency_start_.begin(), adjacency_start_.end() - 1);
  for (const auto& [a, b] : edges_) {  // edges are sorted: neighbours come out ascending
    adjacency_[fill_[a]++] = b;
    adjacency_[fill_[b]++] = a;
  }
  for (int b = 0; b < n; ++b)
    std::sort(adjacency_.begin() + adjacency_start_[b], adjacency_.begin() + adjacency_start_[b + 1]);

  // Each tree hangs from the body held against the world (its rows then stay on their own
  // node), else from its smallest index.
  root_.assign(n, -1);
  for (int b = 0; b < n; ++b) {
    if (!free_body(b)) continue;
    int& r = root_[find(uf_, b)];
    if (r < 0 || (!unary_[r] && unary_[b])) r = b;
  }
  nodes_.resize(n);
  for (Node& node : nodes_) {
    node.parent = -2;  // unvisited
    node.zeroed = false;
  }
  order_.clear();
  for (int b = 0; b < n; ++b) {
    if (!free_body(b) || root_[find(uf_, b)] != b) continue;
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

  // Each row goes to the node that is the child end of its edge (or its one free body);
  // a node's hard rows come before its soft ones.
  const int n_rows = static_cast<int>(rows.size());
  auto owner = [&](int a, int b) {
    const bool fa = free_body(a), fb = free_body(b);
    if (fa && fb) return nodes_[a].parent == b ? a : b;
    return fa ? a : fb ? b : -1;
  };
  row_start_.assign(n + 1, 0);
  std::vector<int>& hard = fill_;
  hard.assign(n, 0);
  for (const ConstraintRow& r : rows) {
    const int o = owner(r.body_a, r.body_b);
    if (o >= 0) ++row_start_[o + 1], ++hard[o];
  }
  for (const HessianRow& r : soft) ++row_start_[owner(r.a, r.b) + 1];
  for (int b = 0; b < n; ++b) {
    if (hard[b] > kMaxRows) return false;
    nodes_[b].hard = hard[b];
    row_start_[b + 1] += row_start_[b];
  }
  row_list_.resize(row_start_[n]);
  hard.assign(row_start_.begin(), row_start_.end() - 1);
  for (int k = 0; k < n_rows; ++k) {
    const int o = owner(rows[k].body_a, rows[k].body_b);
    if (o >= 0) row_list_[hard[o]++] = k;
  }
  for (int k = 0; k < static_cast<int>(soft.size()); ++k)
    row_list_[hard[owner(soft[k].a, soft[k].b)]++] = n_rows + k;
  return true;
}

// H_bb = L Lᵀ with t = L⁻¹ r_b and W ← J L⁻ᵀ in the same sweep; Qᵀ = (W V − J_P)ᵀ with
// V = L⁻¹ H_bP; then S = W Wᵀ + D = L_S L_Sᵀ with λ = L_S⁻¹ (c + W t) and Qᵀ ← Qᵀ L_S⁻ᵀ in
// that sweep. On the leading R >= m rows of W (the rows past m are zero padding: a revolute
// joint's 7 rows take 8 of the 12).
// Flattened: every call inside is inlined (the unrolled factorisation is too large for the
// compiler to inline Eigen's small fixed-size operators into it by itself).
template <int R>
ABD_DENSE_FLATTEN bool TreeKkt::factor_rows(Node& node, Vec12& t, Vec12& lambda) {
  const int m = node.m;
  // L itself is needed for V alone; L_S only through L_Sᵀ and its diagonal (the pivots).
  if (!dense::cholesky_forward<12, R, 12>(node.L, node.Lt, node.L_inv_diagonal, t, node.W, 12,
                                          node.coupling != nullptr))
    return false;
  Mat12& Qt = node.Qt;  // −J_Pᵀ from gather (zero on a root, whose Q is not used)
  if (node.parent >= 0 && node.coupling) {
    node.V = *node.coupling;
    dense::lower_solve(node.L, node.L_inv_diagonal, node.V);
    if (m > 0) Qt.noalias() += node.V.transpose() * node.W.transpose();
  }
  if (m == 0) return true;
  // S = W Wᵀ + D (its leading m columns; rows past m stay zero), column by column with the
  // sum in registers.
  for (int k = 0; k < m; ++k) {
    Eigen::Matrix<double, R, 1> column = Eigen::Matrix<double, R, 1>::Zero();
    for (int j = 0; j < 12; ++j) column += node.W(k, j) * node.W.col(j).template head<R>();
    node.LS.col(k).template head<R>() = column;
  }
  // Only the leading m columns (and R rows) are read: the rest of L_S is left as it is.
  node.LS.diagonal().head(m) += node.D.head(m);
  lambda = node.c;
  lambda.noalias() += node.W.lazyProduct(t);
  // Rows past m are padding (S = I there): only the leading m x m block is factorised, its
  // size a compile-time constant (unrolled, as H_bb's): R − 3 <= m <= R (factor_node).
  auto factor_S = [&](auto size) {
    return dense::cholesky_forward<R, 12, decltype(size)::value>(
        node.LS, node.LSt, node.LS_inv_diagonal, lambda, Qt, m, false);
  };
  switch (m) {
    case R:
      return factor_S(std::integral_constant<int, R>());
    case R - 1:
      return factor_S(std::integral_constant<int, R - 1>());
    case R - 2:
      return factor_S(std::integral_constant<int, R - 2>());
    case R - 3:
      return factor_S(std::integral_constant<int, R - 3>());
    default:
      return dense::cholesky_forward<R, 12>(node.LS, node.LSt, node.LS_inv_diagonal, lambda, Qt,
                                            m, false);
  }
}

bool TreeKkt::factor_node(int b) {
  Node& node = nodes_[b];
  const int m = node.m;
  Vec12 t = node.r;  // L⁻¹ r_b
  Vec12 lambda = Vec12::Zero();
  const bool factored = m <= 4   ? factor_rows<4>(node, t, lambda)
                        : m <= 8 ? factor_rows<8>(node, t, lambda)
                                 : factor_rows<12>(node, t, lambda);
  if (!factored) return false;
  if (m > 0 && node.hard > 0) {  // the hard rows' pivots (the soft ones are at least √D)
    const auto pivots = node.LS.diagonal().head(node.hard);
    const double lo = pivots.minCoeff(), hi = pivots.maxCoeff();
    if (!(lo * lo > kPivotFloor * hi * hi)) return false;
  }
  node.t = t;
  node.lambda = lambda;
  if (node.parent < 0) return true;
  // P's rhs loses C_bᵀ K_b⁻¹ z_b = Vᵀ t − Qᵀ λ (tree_kkt.h): no solve with K_b here.
  Node& parent = nodes_[node.parent];
  if (node.coupling) {
    dense::subtract_gram(node.V, parent.L);
    parent.r.noalias() -= node.V.transpose() * t;
  }
  if (m > 0) {
    dense::add_gram(parent.L, node.Qt, m);
    parent.r.noalias() += node.Qt.lazyProduct(lambda);
  }
  return true;
}

bool TreeKkt::gather(int b, const BlockSystem& system, const std::vector<ConstraintRow>& rows,
                     const VecX& rhs) {
  Node& node = nodes_[b];
  const int n_rows = static_cast<int>(rows.size());
  const auto& soft = system.soft_rows();
  const auto& couplings = system.couplings();
  node.L = system.diagonal(b);
  node.r = rhs.segment<12>(12 * b);
  node.coupling = nullptr;
  if (node.parent >= 0 && !couplings.empty()) {
    const auto it = std::lower_bound(
        couplings.begin(), couplings.end(), std::make_pair(b, node.parent),
        [](const BlockSystem::OffDiagonal& o, const std::pair<int, int>& key) {
          return o.row != key.first ? o.row < key.first : o.col < key.second;
        });
    if (it != couplings.end() && it->row == b && it->col == node.parent) node.coupling = &it->H;
  }
  const int count = row_start_[b + 1] - row_start_[b];
  node.m = std::min(count, kMaxRows);
  if (!node.zeroed) {  // the padding stays zero while the forest (and each node's m) stays
    node.W.setZero();
    node.Qt.setZero();
    node.Lt.setZero();
    node.LSt.setZero();
    node.zeroed = true;
  }
  node.c.setZero();
  node.D.setOnes();  // padding rows: zero rows of compliance 1
  for (int k = 0; k < count; ++k) {
    const int index = row_list_[row_start_[b] + k];
    if (index < n_rows) {
      const ConstraintRow& r = rows[index];
      const bool own_a = r.body_a == b;
      node.W.row(k) = (own_a ? r.ja : r.jb).transpose();
      const int other = own_a ? r.body_b : r.body_a;
      if (node.parent >= 0 && other == node.parent)
        node.Qt.col(k) = -(own_a ? r.jb : r.ja);
      else
        node.Qt.col(k).setZero();
      node.c[k] = r.value;
      node.D[k] = 0.0;
      continue;
    }
    const HessianRow& r = soft[index - n_rows];
    if (!(r.k > 0.0)) return false;
    const bool own_a = r.a == b;
    const Vec12& g = own_a ? r.ga : r.gb;
    const Vec12& gp = own_a ? r.gb : r.ga;
    if (k < kMaxRows) {
      node.W.row(k) = g.transpose();
      node.Qt.col(k) = -gp;
      node.D[k] = 1.0 / r.k;
      continue;
    }
    // No room for the row: its Hessian k (g ⊕ g_P)(g ⊕ g_P)ᵀ goes into the blocks (the
    // parent's were gathered before: parents come first).
    if (node.coupling != &node.own_coupling) {
      node.own_coupling = node.coupling ? *node.coupling : Mat12::Zero();
      node.coupling = &node.own_coupling;
    }
    node.L.noalias() += r.k * g * g.transpose();
    nodes_[node.parent].L.noalias() += r.k * gp * gp.transpose();
    node.own_coupling.noalias() += r.k * g * gp.transpose();
  }
  return true;
}

bool TreeKkt::solve(const BlockSystem& system, const std::vector<ConstraintRow>& rows,
                    const VecX& rhs, VecX& x) {
  signature(system, rows, key_scratch_);
  if (!built_ || key_scratch_ != key_) {
    built_ = false;
    if (!build_forest(system, rows)) return false;
    key_.swap(key_scratch_);
    built_ = true;
  }
  // A failed solve may leave non-finite values in the padding that gather keeps: the next
  // solve builds the forest again.
  built_ = false;
  for (const int b : order_)
    if (!gather(b, system, rows, rhs)) return false;
  for (auto it = order_.rbegin(); it != order_.rend(); ++it)
    if (!factor_node(*it)) return false;

  x.setZero(12 * system.num_bodies());
  Vec12 w, mu;
  for (const int b : order_) {
    // x_b = K_b⁻¹ (z_b − C_b x_P) = L⁻ᵀ (t − V x_P − Wᵀ L_S⁻ᵀ (λ − Q x_P)) (x_P = 0 for a
    // root).
    const Node& node = nodes_[b];
    w = node.t;
    if (node.m > 0) mu = node.lambda;
    if (node.parent >= 0) {
      const Vec12 xp = x.segment<12>(12 * node.parent);
      if (node.coupling) w.noalias() -= node.V.lazyProduct(xp);
      if (node.m > 0) mu.noalias() -= node.Qt.transpose().lazyProduct(xp);
    }
    if (node.m > 0) {
      dense::upper_solve(node.LSt, node.LS_inv_diagonal, mu, node.m);
      w.noalias() -= node.W.transpose().lazyProduct(mu);
    }
    dense::upper_solve(node.Lt, node.L_inv_diagonal, w);
    x.segment<12>(12 * b) = w;
  }
  built_ = all_finite(x);
  return built_;
}

}  // namespace abd
