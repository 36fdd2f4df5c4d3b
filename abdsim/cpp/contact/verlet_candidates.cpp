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

// Appends `more` to `into`, both sorted, keeping the whole sorted (the broad phase's order).
template <class Pairs>
void merge_sorted(Pairs& into, const Pairs& more) {
  const auto middle = into.insert(into.end(), more.begin(), more.end());
  std::inplace_merge(into.begin(), middle, into.end());
}

}  // namespace

void VerletCandidates::mark_uncovered(const ContactMesh& mesh, const std::vector<Vec3>& x,
                                      std::vector<char>& stale) const {
  const double s2 = slack_ * slack_;
  for (int b = 0; b < mesh.num_bodies(); ++b) {
    if (stale[size_t(b)]) continue;
    for (int v = mesh.vertex_offset[b]; v < mesh.vertex_offset[b + 1]; ++v)
      if (!((x[v] - center_[v]).squaredNorm() <= s2)) {  // NaN: not covered
        stale[size_t(b)] = 1;
        break;
      }
  }
}

bool VerletCandidates::recentre(const ContactMesh& mesh, int b, const std::vector<Vec3>& x0,
                                const std::vector<Vec3>* x1) {
  const double s2 = slack_ * slack_;
  for (int v = mesh.vertex_offset[b]; v < mesh.vertex_offset[b + 1]; ++v) {
    center_[v] = x1 ? Vec3(0.5 * (x0[v] + (*x1)[v])) : x0[v];
    // A move longer than 2δ is not covered by any centre (NaN: neither).
    if (!((x0[v] - center_[v]).squaredNorm() <= s2) ||
        (x1 && !(((*x1)[v] - center_[v]).squaredNorm() <= s2))) {
      for (int u = mesh.vertex_offset[b]; u < mesh.vertex_offset[b + 1]; ++u) center_[u] = x0[u];
      return false;
    }
  }
  return true;
}

bool VerletCandidates::requery(BroadPhase& broad_phase, const ContactMesh& mesh,
                               const BroadPhaseQuery& q) {
  BroadPhaseQuery wide = q;
  wide.margin = reach_ + 2.0 * slack_;
  wide.bodies = &stale_;
  Candidates found = broad_phase.query(center_, wide);
  if (found.overflow) return false;  // over the query's cap: no list
  // The stale bodies' old pairs give way to their new ones (no pair is in both: the new
  // ones involve a stale body, the kept ones none), in the broad phase's sorted order.
  auto is_stale = [&](int body) { return stale_[size_t(body)] != 0; };
  auto renew = [](auto& kept, const auto& fresh, auto drop) {
    kept.erase(std::remove_if(kept.begin(), kept.end(), drop), kept.end());
    merge_sorted(kept, fresh);
  };
  renew(list_.point_triangle, found.point_triangle, [&](const std::array<int, 2>& p) {
    return is_stale(mesh.vertex_body[p[0]]) || is_stale(mesh.face_body[p[1]]);
  });
  renew(list_.edge_edge, found.edge_edge, [&](const std::array<int, 2>& p) {
    return is_stale(mesh.edge_body[p[0]]) || is_stale(mesh.edge_body[p[1]]);
  });
  renew(list_.point_ground, found.point_ground,
        [&](int v) { return is_stale(mesh.vertex_body[v]); });
  ++rebuilds_;
  return true;
}

Candidates VerletCandidates::query(BroadPhase& broad_phase, const ContactMesh& mesh,
                                   const std::vector<Vec3>& x0, const std::vector<Vec3>* x1,
                                   const BroadPhaseQuery& q) {
  auto direct = [&](const BroadPhaseQuery& query) {
    return x1 ? broad_phase.query_swept(x0, *x1, query) : broad_phase.query(x0, query);
  };
  const bool servable = !q.edge_triangle && q.margin <= reach_ && q.margin >= 0.0;
  if (!servable) return direct(q);
  const int nb = mesh.num_bodies();
  if (!valid_ || ground_ != q.ground || ground_height_ != q.ground_height ||
      center_.size() != x0.size() || far_.size() != size_t(nb)) {
    // No list: every body is stale.
    list_ = Candidates{};
    center_.assign(x0.size(), Vec3::Zero());
    far_.assign(size_t(nb), 1);
  }
  // Stale: far at the last query, or a vertex now beyond δ of its centre.
  stale_.assign(far_.begin(), far_.end());
  mark_uncovered(mesh, x0, stale_);
  if (x1) mark_uncovered(mesh, *x1, stale_);
  bool any_stale = false, any_far = false;
  for (int b = 0; b < nb; ++b) {
    if (!stale_[size_t(b)]) continue;
    const bool covered = recentre(mesh, b, x0, x1);
    stale_[size_t(b)] = covered;
    far_[size_t(b)] = !covered;
    any_stale = any_stale || covered;
    any_far = any_far || !covered;
  }
  if (any_stale && !requery(broad_phase, mesh, q)) {
    valid_ = false;
    return direct(q);
  }
  ground_ = q.ground;
  ground_height_ = q.ground_height;
  valid_ = true;
  Candidates out = filter(mesh, x0, x1, q);
  if (any_far) {
    // The far bodies' pairs (with anyone) at the real positions.
    BroadPhaseQuery own = q;
    own.bodies = &far_;
    const Candidates found = direct(own);
    if (found.overflow) return direct(q);  // the whole query says where (or fits after all)
    merge_sorted(out.point_triangle, found.point_triangle);
    merge_sorted(out.edge_edge, found.edge_edge);
    merge_sorted(out.point_ground, found.point_ground);
  }
  return out;
}

Candidates VerletCandidates::filter(const ContactMesh& mesh, const std::vector<Vec3>& x0,
                                    const std::vector<Vec3>* x1, const BroadPhaseQuery& q) const {
  const std::vector<double>& r = mesh.body_thickness;
  auto far = [&](int body) { return far_[size_t(body)] != 0; };
  Candidates out;
  for (const auto& [v, f] : list_.point_triangle) {
    const int a = mesh.vertex_body[v], b = mesh.face_body[f];
    if (far(a) || far(b)) continue;
    if (boxes_within(point_box(v, x0, x1), leaf_box(mesh.faces[f], x0, x1), q.margin + r[a] + r[b]))
      out.point_triangle.push_back({v, f});
  }
  for (const auto& [i, j] : list_.edge_edge) {
    const int a = mesh.edge_body[i], b = mesh.edge_body[j];
    if (far(a) || far(b)) continue;
    if (boxes_within(leaf_box(mesh.edges[i], x0, x1), leaf_box(mesh.edges[j], x0, x1),
                     q.margin + r[a] + r[b]))
      out.edge_edge.push_back({i, j});
  }
  if (q.ground)
    for (int v : list_.point_ground) {
      if (far(mesh.vertex_body[v])) continue;
      const double z = x1 ? std::min(x0[v].z(), (*x1)[v].z()) : x0[v].z();
      if (z <= q.ground_height + q.margin + r[mesh.vertex_body[v]]) out.point_ground.push_back(v);
    }
  return out;
}

}  // namespace abd::contact
