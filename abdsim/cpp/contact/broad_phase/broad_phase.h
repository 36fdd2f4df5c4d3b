// Candidate primitive pairs for the contact term. Two levels:
//  1. bodies: coal's dynamic AABB tree over per-body world boxes (body_pairs.h), each box
//     grown by half the query margin plus the body's thickness, keeps the body pairs that may
//     be close; the `bodies_may_collide` filter (contact table, fixed–fixed) drops the rest;
//  2. primitives: per-body coal BVHs (body_bvh.h) are traversed against each other
//     (bvh_traversal.h): vertices × triangles both ways and edges × edges. The trees stay in
//     rest space; their boxes are mapped to world space node by node through each body's
//     affine map, recovered from its vertices (affine_frame.h), so a query costs the nodes it
//     visits, not a refit of every tree it touches (dense robot meshes: ~10^5 triangles a
//     link). A body without a recoverable map is refit instead.
// A body is paired with itself only when its geometry has self_collision = 1 (then pairs
// sharing a vertex are skipped). The ground is a height test on the vertices of the bodies
// whose box reaches it.
//
// The result is a superset of the pairs within the margin (box tests are conservative); the
// contact term computes exact distances. Output is sorted, so it is deterministic.
#pragma once
#include <array>
#include <functional>
#include <memory>
#include <vector>

#include "contact/broad_phase/affine_frame.h"
#include "contact/broad_phase/body_bvh.h"
#include "contact/broad_phase/body_pairs.h"
#include "contact/broad_phase/bvh_traversal.h"
#include "contact/contact_mesh.h"

namespace abd::contact {

struct Candidates {
  std::vector<std::array<int, 2>> point_triangle;  // (global vertex, global face)
  std::vector<std::array<int, 2>> edge_edge;       // (global edge, global edge), first < second
  std::vector<int> point_ground;                   // global vertex
  std::vector<std::array<int, 2>> edge_triangle;   // (global edge, global face): intersections
  // The query stopped at BroadPhaseQuery::max_candidates pairs (the lists above are then
  // empty): the bodies of the pair it was collecting (b = -1: the ground).
  bool overflow = false;
  std::array<int, 2> overflow_bodies{-1, -1};

  size_t size() const {
    return point_triangle.size() + edge_edge.size() + point_ground.size() + edge_triangle.size();
  }
};

struct BroadPhaseQuery {
  double margin = 0.0;         // find pairs closer than margin + both thickness radii
  bool ground = false;         // also vertices near the ground half-space z >= ground_height
  double ground_height = 0.0;
  bool edge_triangle = false;  // also edge–triangle pairs (initial intersection check)
  // At most this many pairs (0: no limit): a query that would collect more stops early and
  // says so (Candidates::overflow) instead of growing its lists without bound (a swept query
  // of a body moving far through dense meshes finds hundreds of millions of box pairs).
  size_t max_candidates = 0;
  // Only the pairs (and ground, self-contact) involving these bodies (one flag a body; null:
  // all): a partial answer for callers that keep the rest (verlet_candidates.h).
  const std::vector<char>* bodies = nullptr;
};

class BroadPhase {
 public:
  using BodyFilter = std::function<bool(int body_a, int body_b)>;  // body_b = -1: the ground

  BroadPhase(const ContactMesh& mesh, BodyFilter bodies_may_collide);

  // Primitives close at positions x.
  Candidates query(const std::vector<Vec3>& x, const BroadPhaseQuery& q);
  // Primitives that may come close while the vertices move linearly from x0 to x1.
  Candidates query_swept(const std::vector<Vec3>& x0, const std::vector<Vec3>& x1,
                         const BroadPhaseQuery& q);

 private:
  // Body boxes come from a pass over the vertices (tight: the images of rest boxes through
  // the affine maps are looser and let more body pairs through to the trees, which cost
  // more than the pass). A body's affine maps are recovered (or, failing that, its three
  // BVHs refit to x0, or swept x0 → x1) only when some pair, self-collision or the ground
  // needs them; the ground descends the vertex tree of the bodies near it.
  Candidates collect(const std::vector<Vec3>& x0, const std::vector<Vec3>* x1,
                     const BroadPhaseQuery& q);
  bool map_affine(int b);  // recovers b's maps (once per query); false: b must be refit
  void fit(int b);
  void collect_all(const std::vector<coal::AABB>& boxes, const BroadPhaseQuery& q,
                   Candidates& out);
  void collect_ground(int b, double z_max, Candidates& out) const;
  TreeBoxes tree_boxes(int b, const Bvh* tree) const;
  void collect_pair(int a, int b, double margin, const BroadPhaseQuery& q, Candidates& out) const;
  void collect_self(int a, double margin, const BroadPhaseQuery& q, Candidates& out) const;
  std::vector<Vec3> body_slice(const std::vector<Vec3>& x, int b) const;

  const ContactMesh& mesh_;
  BodyFilter may_collide_;
  std::vector<std::unique_ptr<BodyBvh>> bvhs_;
  std::vector<AffineFrame> frames_;
  // Per query: the positions, which bodies are ready (fitted_), and for those whose trees
  // stay at rest (affine_) their maps at x0 and x1.
  const std::vector<Vec3>* x0_ = nullptr;
  const std::vector<Vec3>* x1_ = nullptr;
  std::vector<char> fitted_, affine_;
  std::vector<AffineMap> map0_, map1_;
  // Pairs the query may still collect (BroadPhaseQuery::max_candidates); take() spends one.
  mutable size_t room_ = 0;
  void take() const;
  // Node boxes of the mapped bodies with small trees, at this query (vertices, edges, faces
  // trees; see TreeBoxes::cached); cached_[b] says whether b's are filled.
  void cache_node_boxes(int b);
  std::vector<std::array<std::vector<coal::AABB>, 3>> node_boxes_;
  std::vector<char> cached_;
  BodyPairFinder body_pairs_;
};

}  // namespace abd::contact
