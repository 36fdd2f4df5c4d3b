#include "contact/broad_phase/broad_phase.h"

#include <algorithm>
#include <limits>

#include "contact/broad_phase/bvh_traversal.h"

namespace abd::contact {
namespace {
// Bodies with more vertices than this take their broad-phase box from their affine map.
constexpr int kMappedBoxVertices = 64;

template <class T>
void sort_unique(std::vector<T>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

bool shares_vertex(const std::array<int, 2>& e, const std::array<int, 2>& f) {
  return e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1];
}

// Thrown by take() when a query's room is spent; collect() catches it.
struct Overflow {};

template <size_t N>
bool contains(const std::array<int, N>& prim, int v) {
  return std::find(prim.begin(), prim.end(), v) != prim.end();
}

}  // namespace

BroadPhase::BroadPhase(const ContactMesh& mesh, BodyFilter bodies_may_collide)
    : mesh_(mesh), may_collide_(std::move(bodies_may_collide)), body_pairs_(mesh.num_bodies()) {
  for (int b = 0; b < mesh.num_bodies(); ++b) {
    const int v0 = mesh.vertex_offset[b];
    std::vector<std::array<int, 2>> edges;
    std::vector<std::array<int, 3>> faces;
    for (int e = mesh.edge_offset[b]; e < mesh.edge_offset[b + 1]; ++e)
      edges.push_back({mesh.edges[e][0] - v0, mesh.edges[e][1] - v0});
    for (int f = mesh.face_offset[b]; f < mesh.face_offset[b + 1]; ++f)
      faces.push_back({mesh.faces[f][0] - v0, mesh.faces[f][1] - v0, mesh.faces[f][2] - v0});
    const std::vector<Vec3> rest = body_slice(mesh.rest, b);
    bvhs_.push_back(std::make_unique<BodyBvh>(rest, edges, faces));
    frames_.emplace_back(rest);
  }
  map0_.resize(size_t(mesh.num_bodies()));
  map1_.resize(size_t(mesh.num_bodies()));
  node_boxes_.resize(size_t(mesh.num_bodies()));
}

std::vector<Vec3> BroadPhase::body_slice(const std::vector<Vec3>& x, int b) const {
  return {x.begin() + mesh_.vertex_offset[b], x.begin() + mesh_.vertex_offset[b + 1]};
}

Candidates BroadPhase::query(const std::vector<Vec3>& x, const BroadPhaseQuery& q) {
  return collect(x, nullptr, q);
}

Candidates BroadPhase::query_swept(const std::vector<Vec3>& x0, const std::vector<Vec3>& x1,
                                   const BroadPhaseQuery& q) {
  return collect(x0, &x1, q);
}

bool BroadPhase::map_affine(int b) {
  if (fitted_[b]) return affine_[b];
  const Vec3* first0 = x0_->data() + mesh_.vertex_offset[b];
  const Vec3* first1 = x1_ ? x1_->data() + mesh_.vertex_offset[b] : nullptr;
  // Once refit, a body's trees are no longer at rest: it stays on the refit path.
  affine_[b] = bvhs_[b]->at_rest() && frames_[b].recover(first0, map0_[b]) &&
               (!first1 || frames_[b].recover(first1, map1_[b]));
  fitted_[b] = affine_[b];
  return affine_[b];
}

// Trees up to this many nodes in all get every node box computed once per query: cheap
// next to the dual-tree descents, which ask for each node once per node of the other tree
// (a heap of boxes spent 30% of its time there). Bigger meshes (robot links) keep computing
// only the nodes their descents visit.
constexpr int kMaxCachedNodes = 1024;

void BroadPhase::cache_node_boxes(int b) {
  const BodyBvh& bvh = *bvhs_[b];
  const std::array<const Bvh*, 3> trees{bvh.vertices(), bvh.edges(), bvh.faces()};
  int nodes = 0;
  for (const Bvh* t : trees) nodes += t ? int(t->getNumBVs()) : 0;
  if (nodes > kMaxCachedNodes) return;
  for (int k = 0; k < 3; ++k) {
    std::vector<coal::AABB>& boxes = node_boxes_[b][k];
    boxes.clear();
    if (!trees[k]) continue;
    const TreeBoxes t = tree_boxes(b, trees[k]);
    for (int i = 0; i < int(trees[k]->getNumBVs()); ++i) boxes.push_back(t.node(i));
  }
  cached_[b] = 1;
}

void BroadPhase::fit(int b) {
  if (fitted_[b]) return;
  if (map_affine(b)) {
    cache_node_boxes(b);
    return;
  }
  fitted_[b] = 1;
  if (x1_)
    bvhs_[b]->refit_swept(body_slice(*x0_, b), body_slice(*x1_, b));
  else
    bvhs_[b]->refit(body_slice(*x0_, b));
}

TreeBoxes BroadPhase::tree_boxes(int b, const Bvh* tree) const {
  TreeBoxes t;
  t.tree = tree;
  if (!affine_[b]) return t;
  if (cached_[b]) {
    const BodyBvh& bvh = *bvhs_[b];
    const int k = tree == bvh.vertices() ? 0 : tree == bvh.edges() ? 1 : 2;
    t.cached = node_boxes_[b][k].data();
    return t;
  }
  t.affine0 = &map0_[b];
  t.x0 = x0_->data() + mesh_.vertex_offset[b];
  if (x1_) {
    t.affine1 = &map1_[b];
    t.x1 = x1_->data() + mesh_.vertex_offset[b];
  }
  return t;
}

Candidates BroadPhase::collect(const std::vector<Vec3>& x0, const std::vector<Vec3>* x1,
                               const BroadPhaseQuery& q) {
  const int n = mesh_.num_bodies();
  Candidates out;
  x0_ = &x0;
  x1_ = x1;
  fitted_.assign(static_cast<size_t>(n), 0);
  affine_.assign(static_cast<size_t>(n), 0);
  cached_.assign(static_cast<size_t>(n), 0);
  // Each body's box (around its vertices, at x0 and x1 when swept) grows by half the margin
  // plus its own thickness, so two boxes overlap whenever their bodies may be within
  // margin + r_a + r_b.
  // A body of many vertices takes the box of its rest tree's root under its affine map(s)
  // (O(1), a little larger than its vertices' box) instead of a pass over its vertices: a
  // 5,000-vertex robot spent a tenth of its step in that pass.
  std::vector<coal::AABB> boxes(static_cast<size_t>(n));
  for (int b = 0; b < n; ++b) {
    const double grow = 0.5 * q.margin + mesh_.body_thickness[b];
    Vec3 lo, hi;
    const bool many = mesh_.vertex_offset[b + 1] - mesh_.vertex_offset[b] > kMappedBoxVertices;
    if (many && bvhs_[b]->vertices() && map_affine(b)) {
      const coal::AABB root = tree_boxes(b, bvhs_[b]->vertices()).node(0);
      lo = root.min_;
      hi = root.max_;
    } else {
      lo = hi = x0[mesh_.vertex_offset[b]];
      for (int v = mesh_.vertex_offset[b]; v < mesh_.vertex_offset[b + 1]; ++v) {
        lo = lo.cwiseMin(x0[v]);
        hi = hi.cwiseMax(x0[v]);
        if (x1) {
          lo = lo.cwiseMin((*x1)[v]);
          hi = hi.cwiseMax((*x1)[v]);
        }
      }
    }
    boxes[b] = coal::AABB(Vec3(lo.array() - grow), Vec3(hi.array() + grow));
  }
  room_ = q.max_candidates > 0 ? q.max_candidates : std::numeric_limits<size_t>::max();
  try {
    collect_all(boxes, q, out);
  } catch (const Overflow&) {
    const std::array<int, 2> where = out.overflow_bodies;
    out = Candidates{};  // what was collected is partial: of no use to the caller
    out.overflow = true;
    out.overflow_bodies = where;
    x0_ = x1_ = nullptr;
    return out;
  }
  sort_unique(out.point_triangle);
  sort_unique(out.edge_edge);
  sort_unique(out.point_ground);
  sort_unique(out.edge_triangle);
  x0_ = x1_ = nullptr;  // the caller's positions are not ours to keep
  return out;
}

// The body pairs, self-collisions and the ground of one query (boxes: the bodies' boxes).
// out.overflow_bodies follows what is being collected, for the overflow report.
void BroadPhase::collect_all(const std::vector<coal::AABB>& boxes, const BroadPhaseQuery& q,
                             Candidates& out) {
  const int n = mesh_.num_bodies();
  auto wanted = [&](int b) { return !q.bodies || (*q.bodies)[size_t(b)]; };
  for (const auto& [a, b] : body_pairs_.overlapping(boxes))
    if ((wanted(a) || wanted(b)) && may_collide_(a, b)) {
      out.overflow_bodies = {a, b};
      fit(a);
      fit(b);
      collect_pair(a, b, q.margin + mesh_.body_thickness[a] + mesh_.body_thickness[b], q, out);
    }
  for (int b = 0; b < n; ++b) {
    if (!wanted(b)) continue;
    if (mesh_.self_collision[b] && may_collide_(b, b)) {
      out.overflow_bodies = {b, b};
      fit(b);
      collect_self(b, q.margin + 2.0 * mesh_.body_thickness[b], q, out);
    }
    const double z_max = q.ground_height + q.margin + mesh_.body_thickness[b];
    // boxes[b].min_ z is (at most) the lowest vertex minus half the margin and the thickness.
    if (q.ground && boxes[b].min_[2] + 0.5 * q.margin + mesh_.body_thickness[b] <= z_max &&
        may_collide_(b, -1)) {
      out.overflow_bodies = {b, -1};
      collect_ground(b, z_max, out);
    }
  }
}

void BroadPhase::take() const {
  if (room_ == 0) throw Overflow{};
  --room_;
}

void BroadPhase::collect_ground(int b, double z_max, Candidates& out) const {
  const std::vector<Vec3>& x0 = *x0_;
  const int first = mesh_.vertex_offset[b];
  if (!affine_[b]) {  // a pass over the vertices (lowest of x0, x1) costs what a refit would
    for (int v = first; v < mesh_.vertex_offset[b + 1]; ++v) {
      const double z = x1_ ? std::min(x0[v].z(), (*x1_)[v].z()) : x0[v].z();
      if (z <= z_max) {
        take();
        out.point_ground.push_back(v);
      }
    }
    return;
  }
  // Descend the vertex tree: only the nodes whose box reaches down to z_max (a leaf's box is
  // its vertex, lowest of x0 and x1: the same test as the pass above).
  const TreeBoxes t = tree_boxes(b, bvhs_[b]->vertices());
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    if (t.node(i).min_[2] > z_max) continue;
    const auto& node = t.tree->getBV(unsigned(i));
    if (node.isLeaf()) {
      take();
      out.point_ground.push_back(first + node.primitiveId());
    } else {
      stack.push_back(node.rightChild());
      stack.push_back(node.leftChild());
    }
  }
}

void BroadPhase::collect_pair(int a, int b, double margin, const BroadPhaseQuery& q,
                              Candidates& out) const {
  const BodyBvh& A = *bvhs_[a];
  const BodyBvh& B = *bvhs_[b];
  const ContactMesh& m = mesh_;
  auto point_triangle = [&](const BodyBvh& P, int p_body, const BodyBvh& T, int t_body) {
    if (!T.faces()) return;
    for_each_close_leaf_pair(tree_boxes(p_body, P.vertices()), tree_boxes(t_body, T.faces()),
                             margin, [&](int v, int f) {
      take();
      out.point_triangle.push_back({m.vertex_offset[p_body] + v, m.face_offset[t_body] + f});
    });
  };
  point_triangle(A, a, B, b);
  point_triangle(B, b, A, a);
  if (A.edges() && B.edges())
    for_each_close_leaf_pair(tree_boxes(a, A.edges()), tree_boxes(b, B.edges()), margin,
                             [&](int i, int j) {
      take();
      out.edge_edge.push_back({m.edge_offset[a] + i, m.edge_offset[b] + j});
    });
  if (!q.edge_triangle) return;
  auto edge_triangle = [&](const BodyBvh& E, int e_body, const BodyBvh& T, int t_body) {
    if (!E.edges() || !T.faces()) return;
    for_each_close_leaf_pair(tree_boxes(e_body, E.edges()), tree_boxes(t_body, T.faces()),
                             q.margin, [&](int e, int f) {
      take();
      out.edge_triangle.push_back({m.edge_offset[e_body] + e, m.face_offset[t_body] + f});
    });
  };
  edge_triangle(A, a, B, b);
  edge_triangle(B, b, A, a);
}

void BroadPhase::collect_self(int a, double margin, const BroadPhaseQuery& q,
                              Candidates& out) const {
  const BodyBvh& A = *bvhs_[a];
  const ContactMesh& m = mesh_;
  if (A.faces())
    for_each_close_leaf_pair(tree_boxes(a, A.vertices()), tree_boxes(a, A.faces()), margin,
                             [&](int v, int f) {
      const int gv = m.vertex_offset[a] + v, gf = m.face_offset[a] + f;
      if (contains(m.faces[gf], gv)) return;
      take();
      out.point_triangle.push_back({gv, gf});
    });
  if (A.edges())
    for_each_close_leaf_pair(tree_boxes(a, A.edges()), tree_boxes(a, A.edges()), margin,
                             [&](int i, int j) {
      const int ei = m.edge_offset[a] + i, ej = m.edge_offset[a] + j;
      if (ei >= ej || shares_vertex(m.edges[ei], m.edges[ej])) return;
      take();
      out.edge_edge.push_back({ei, ej});
    });
  if (q.edge_triangle && A.edges() && A.faces())
    for_each_close_leaf_pair(tree_boxes(a, A.edges()), tree_boxes(a, A.faces()), q.margin,
                             [&](int i, int f) {
      const int e = m.edge_offset[a] + i, gf = m.face_offset[a] + f;
      if (!contains(m.faces[gf], m.edges[e][0]) && !contains(m.faces[gf], m.edges[e][1]))
      {
        take();
        out.edge_triangle.push_back({e, gf});
      }
    });
}

}  // namespace abd::contact
