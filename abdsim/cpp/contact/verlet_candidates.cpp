#include "contact/verlet_candidates.h"

#include <algorithm>

#include "contact/broad_phase/bvh_traversal.h"

namespace abd::contact {
namespace {

// The box the BVH gives a leaf: around the primitive's vertices, at both ends when swept.
template <size_t N>
coal::AABB leaf_box(const std::array<int, N>& v, const std::vector<Vec3>& x0,
                    const std::vector<Vec3>* x1) {
  coal::AABB box(x0[v[0]]);
  for (int k : v) {
    box += x0[k];
    if (x1) box += (*x1)[k];
  }
  return box;
}

coal::AABB point_box(int v, const std::vector<Vec3>& x0, const std::vector<Vec3>* x1) {
  coal::AABB box(x0[v]);
  if (x1) box += (*x1)[v];
  return box;
}

}  // namespace

bool VerletCandidates::covers(const std::vector<Vec3>& x) const {
  if (x.size() != center_.size()) return false;
  const double s2 = slack_ * slack_;
  for (size_t i = 0; i < x.size(); ++i)
    if (!((x[i] - center_[i]).squaredNorm() <= s2)) return false;  // NaN: not covered
  return true;
}

Candidates VerletCandidates::query(BroadPhase& broad_phase, const ContactMesh& mesh,
                                   const std::vector<Vec3>& x0, const std::vector<Vec3>* x1,
                                   const BroadPhaseQuery& q) {
  const bool servable = !q.edge_triangle && q.margin <= reach_ && q.margin >= 0.0;
  if (!servable) return x1 ? broad_phase.query_swept(x0, *x1, q) : broad_phase.query(x0, q);
  const bool fresh = valid_ && ground_ == q.ground && ground_height_ == q.ground_height &&
                     covers(x0) && (!x1 || covers(*x1));
  if (!fresh) {
    // A new list centred on the move (its midpoint); a move longer than 2δ is not covered
    // by any list: queried directly.
    std::vector<Vec3> center = x0;
    if (x1)
      for (size_t i = 0; i < center.size(); ++i) center[i] = 0.5 * (x0[i] + (*x1)[i]);
    center_.swap(center);
    if (!covers(x0) || (x1 && !covers(*x1))) {
      valid_ = false;
      return x1 ? broad_phase.query_swept(x0, *x1, q) : broad_phase.query(x0, q);
    }
    BroadPhaseQuery wide = q;
    wide.margin = reach_ + 2.0 * slack_;
    list_ = broad_phase.query(center_, wide);
    if (list_.overflow) {  // over the query's cap: no list; the query answers (or overflows)
      valid_ = false;
      return x1 ? broad_phase.query_swept(x0, *x1, q) : broad_phase.query(x0, q);
    }
    ground_ = q.ground;
    ground_height_ = q.ground_height;
    valid_ = true;
    ++rebuilds_;
  }
  return filter(mesh, x0, x1, q);
}

Candidates VerletCandidates::filter(const ContactMesh& mesh, const std::vector<Vec3>& x0,
                                    const std::vector<Vec3>* x1, const BroadPhaseQuery& q) const {
  const std::vector<double>& r = mesh.body_thickness;
  Candidates out;
  for (const auto& [v, f] : list_.point_triangle) {
    const int a = mesh.vertex_body[v], b = mesh.face_body[f];
    if (boxes_within(point_box(v, x0, x1), leaf_box(mesh.faces[f], x0, x1), q.margin + r[a] + r[b]))
      out.point_triangle.push_back({v, f});
  }
  for (const auto& [i, j] : list_.edge_edge) {
    const int a = mesh.edge_body[i], b = mesh.edge_body[j];
    if (boxes_within(leaf_box(mesh.edges[i], x0, x1), leaf_box(mesh.edges[j], x0, x1),
                     q.margin + r[a] + r[b]))
      out.edge_edge.push_back({i, j});
  }
  if (q.ground)
    for (int v : list_.point_ground) {
      const double z = x1 ? std::min(x0[v].z(), (*x1)[v].z()) : x0[v].z();
      if (z <= q.ground_height + q.margin + r[mesh.vertex_body[v]]) out.point_ground.push_back(v);
    }
  return out;
}

}  // namespace abd::contact
