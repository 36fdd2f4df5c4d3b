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

double IpcContactTerm::max_step(const VecX& q, const VecX& dq) const {
  if (dq.size() != q.size()) throw std::invalid_argument("max_step: dq must have the size of q");
  // margin 0: only the thickness must stay clear. All bodies take one step length: it stays
  // within every body's checked (possibly shortened) move.
  const Sweep sweep = bounded_sweep(q, dq, 0.0);
  double alpha = 1.0;
  for (double t : sweep.toi) alpha = std::min(alpha, t);
  for (int b = 0; b < mesh_.num_bodies(); ++b)
    if (dq.segment<12>(12 * b).any()) alpha = std::min(alpha, sweep.scale[size_t(b)]);
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
  // within reach of the barrier anywhere on the (checked part of the) path
  swept_.valid = false;
  Sweep sweep = bounded_sweep(q, dq, settings_.d_hat);
  swept_.q0 = q;
  swept_.dq = dq;
  for (int b = 0; b < nb; ++b) {
    const double s = sweep.scale[size_t(b)];
    if (s == 1.0) continue;
    swept_.dq.segment<12>(12 * b) *= s;
    // A shortened body's step stops where its check did.
    if (movable[b]) bound[b] = std::min(bound[b], s);
  }
  swept_.candidates = std::move(sweep.candidates);
  swept_.scale = std::move(sweep.scale);
  swept_.reach = std::move(sweep.reach);
  swept_.valid = true;
  const int n = int(sweep.stencils.size());
  for (int i = 0; i < n; ++i) {
    const ContactStencil& s = sweep.stencils[size_t(i)];
    const int a = s.bodies[0], b = s.bodies[1];
    for (int body : {a, b}) {
      if (body < 0 || !movable[body]) continue;
      near[body] = 1;
      bound[body] = std::min(bound[body], sweep.toi[size_t(i)]);
    }
    // Candidates come sorted by primitive, so one body pair's run of them would repeat its
    // link hundreds of times (a heap of 100 boxes: ~2,800 candidates a sweep): one suffices.
    const bool repeat = !links.empty() && links.back().a == a && links.back().b == b;
    if (b >= 0 && a != b && movable[a] && movable[b] && !repeat) links.push_back({a, b});
  }
}

bool IpcContactTerm::on_swept_path(const VecX& q, std::vector<double>& times) const {
  if (!swept_.valid || q.size() != swept_.q0.size()) return false;
  times.resize(size_t(q.size() / 12));
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
    times[size_t(b)] = std::clamp(t, 0.0, 1.0);  // the bound's slack covers the ulps cut off
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
  const Candidates c = bounded_query(x, query);

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
