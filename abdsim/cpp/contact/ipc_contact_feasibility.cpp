// IpcContactTerm: what keeps configurations feasible — the CCD step bound, minimum distances,
// and the initial-configuration check.
#include <algorithm>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "contact/ccd/additive_ccd.h"
#include "contact/ground/ground_plane.h"
#include "contact/intersection/segment_triangle.h"
#include "contact/ipc_contact_term.h"
#include "contact/parallel.h"

namespace abd {
using namespace contact;

namespace {

// Time of impact of one candidate pair moving linearly from x0 to x1.
double candidate_toi(const ContactStencil& s, const std::vector<Vec3>& x0,
                     const std::vector<Vec3>& x1, double ground_height, CcdOptions o) {
  o.min_distance = s.xi;
  const auto& v = s.vertices;
  switch (s.kind) {
    case StencilKind::PointTriangle:
      return point_triangle_ccd(x0[v[0]], x0[v[1]], x0[v[2]], x0[v[3]], x1[v[0]], x1[v[1]],
                                x1[v[2]], x1[v[3]], o);
    case StencilKind::EdgeEdge:
      return edge_edge_ccd(x0[v[0]], x0[v[1]], x0[v[2]], x0[v[3]], x1[v[0]], x1[v[1]], x1[v[2]],
                           x1[v[3]], o);
    default: return point_ground_ccd(x0[v[0]], x1[v[0]], ground_height, o);
  }
}

std::string describe(const ContactStencil& s) {
  std::ostringstream os;
  switch (s.kind) {
    case StencilKind::PointTriangle:
      os << "vertex " << s.primitives[0] << " and triangle " << s.primitives[1];
      break;
    case StencilKind::EdgeEdge:
      os << "edge " << s.primitives[0] << " and edge " << s.primitives[1];
      break;
    default: os << "vertex " << s.primitives[0];
  }
  return os.str();
}

}  // namespace

// Candidate pairs of the straight move x0 → x1 that come within `margin` (beyond their
// thickness), and their ACCD times of impact (1: none on the step).
void IpcContactTerm::swept_tois(const std::vector<Vec3>& x0, const std::vector<Vec3>& x1,
                                double margin, std::vector<ContactStencil>& stencils,
                                std::vector<double>& toi, Candidates* keep) const {
  BroadPhaseQuery query;
  query.margin = margin;
  query.ground = settings_.ground;
  query.ground_height = settings_.ground_height;
  const Candidates c =
      timed(broad_phase_seconds_, [&] { return verlet_.query(broad_phase_, mesh_, x0, &x1, query); });
  stencils.clear();
  stencils.reserve(c.point_triangle.size() + c.edge_edge.size() + c.point_ground.size());
  for (const auto& [v, f] : c.point_triangle) stencils.push_back(point_triangle_stencil(mesh_, v, f, 0.0));
  for (const auto& [a, b] : c.edge_edge) stencils.push_back(edge_edge_stencil(mesh_, a, b, 0.0));
  for (int v : c.point_ground) stencils.push_back(point_ground_stencil(mesh_, v, 0.0));
  if (keep) *keep = c;

  CcdOptions options;
  options.target = settings_.ccd_target;
  const int n = int(stencils.size());
  toi.assign(size_t(n), 1.0);
  for_each_stencil(n, n >= kMinParallelCcd, threads_, [&](int i) {
    // Pairs that do not move relative to each other keep their distance: no CCD needed.
    const ContactStencil& s = stencils[size_t(i)];
    bool moving = false;
    for (int k = 0; k < s.nv && !moving; ++k) moving = x0[s.vertices[k]] != x1[s.vertices[k]];
    if (moving) toi[size_t(i)] = candidate_toi(s, x0, x1, settings_.ground_height, options);
  });
}

double IpcContactTerm::max_step(const VecX& q, const VecX& dq) const {
  if (dq.size() != q.size()) throw std::invalid_argument("max_step: dq must have the size of q");
  std::vector<ContactStencil> stencils;
  std::vector<double> toi;
  // margin 0: only the thickness must stay clear
  std::vector<Vec3> scratch;
  swept_tois(vertices_at(q, scratch), mesh_.world_vertices(q + dq), 0.0, stencils, toi);
  double alpha = 1.0;
  for (double t : toi) alpha = std::min(alpha, t);
  return alpha;
}

void IpcContactTerm::body_max_steps(const VecX& q, const VecX& dq,
                                    const std::vector<unsigned char>& movable, VecX& bound,
                                    std::vector<unsigned char>& near,
                                    std::vector<BodyLink>& links) const {
  const int nb = mesh_.num_bodies();
  if (dq.size() != q.size() || bound.size() != nb || int(near.size()) != nb ||
      int(movable.size()) != nb)
    throw std::invalid_argument("body_max_steps: dq, bound, near and movable must match q");
  std::vector<ContactStencil> stencils;
  std::vector<double> toi;
  // within reach of the barrier anywhere on the path
  swept_.valid = false;
  std::vector<Vec3> scratch;
  swept_tois(vertices_at(q, scratch), mesh_.world_vertices(q + dq), settings_.d_hat, stencils,
             toi, &swept_.candidates);
  swept_.q0 = q;
  swept_.dq = dq;
  swept_.valid = true;
  const int n = int(stencils.size());
  for (int i = 0; i < n; ++i) {
    const ContactStencil& s = stencils[size_t(i)];
    const int a = s.bodies[0], b = s.bodies[1];
    for (int body : {a, b}) {
      if (body < 0 || !movable[body]) continue;
      near[body] = 1;
      bound[body] = std::min(bound[body], toi[size_t(i)]);
    }
    if (b >= 0 && a != b && movable[a] && movable[b]) links.push_back({a, b});
  }
}

bool IpcContactTerm::on_swept_path(const VecX& q) const {
  if (!swept_.valid || q.size() != swept_.q0.size()) return false;
  // Rounding of q0 + α dq: a few ulps of the coordinates' size.
  constexpr double kUlps = 8.0 * std::numeric_limits<double>::epsilon();
  for (Eigen::Index b = 0; b < q.size() / 12; ++b) {
    const Vec12 d = q.segment<12>(12 * b) - swept_.q0.segment<12>(12 * b);
    const Vec12 s = swept_.dq.segment<12>(12 * b);
    const double scale = swept_.q0.segment<12>(12 * b).cwiseAbs().maxCoeff() +
                         s.cwiseAbs().maxCoeff();
    const double ss = s.squaredNorm();
    const double t = ss > 0.0 ? d.dot(s) / ss : 0.0;
    if (t < -kUlps || t > 1.0 + kUlps) return false;
    if ((d - t * s).cwiseAbs().maxCoeff() > kUlps * scale) return false;
  }
  return true;
}

double IpcContactTerm::min_distance(const VecX& q, double max_distance) const {
  const double reach = max_distance > 0.0 ? max_distance : settings_.d_hat;
  if (reach == settings_.d_hat && active_.q.size() == q.size() && active_.q == q)
    return active_.min_gap;
  return build_active_set(q, reach).min_gap;
}

void IpcContactTerm::check_initial(const VecX& q) const {
  std::vector<Vec3> x = mesh_.world_vertices(q);
  BroadPhaseQuery query;  // margin 0: touching, within thickness, or crossing
  query.ground = settings_.ground;
  query.ground_height = settings_.ground_height;
  query.edge_triangle = true;
  const Candidates c = timed(broad_phase_seconds_, [&] { return broad_phase_.query(x, query); });

  for (const auto& [e, f] : c.edge_triangle) {
    const auto& ev = mesh_.edges[e];
    const auto& fv = mesh_.faces[f];
    if (segment_triangle_intersect(x[ev[0]], x[ev[1]], x[fv[0]], x[fv[1]], x[fv[2]])) {
      std::ostringstream os;
      os << "contact: bodies " << mesh_.edge_body[e] << " and " << mesh_.face_body[f]
         << " intersect (edge " << e << " crosses triangle " << f << ")";
      throw std::invalid_argument(os.str());
    }
  }
  const ActiveSet set = select_active(mesh_, table_, c, q, std::move(x), 0.0, settings_.ground_height);
  if (set.infeasible < 0) return;
  const ContactStencil& s = set.stencils[size_t(set.infeasible)];
  std::ostringstream os;
  if (s.kind == StencilKind::PointGround) {
    os << "contact: body " << s.bodies[0] << " reaches into the ground (" << describe(s)
       << " at z = " << set.x[s.vertices[0]].z() << ", ground at " << settings_.ground_height
       << ", thickness " << s.xi << ")";
  } else {
    os << "contact: bodies " << s.bodies[0] << " and " << s.bodies[1]
       << " are in contact or closer than their contact thickness " << s.xi << " ("
       << describe(s) << ")";
  }
  throw std::invalid_argument(os.str());
}

}  // namespace abd
