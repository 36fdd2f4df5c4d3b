#include "contact/swept_reach.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace abd::contact {
namespace {
// Relative allowance on reach: rounding of the trial's vertices (computed from q, not as
// x0 + t Δ) and of the distances is ~1e-16 of the coordinates, far below it.
constexpr double kRelativeSlack = 1e-2;
// Absolute allowance, per unit of the coordinates' magnitude.
constexpr double kAbsoluteSlack = 1e-10;
}  // namespace

PathReach path_reach(const ContactStencil& s, const std::vector<Vec3>& x0,
                     const std::array<Vec3, 4>& p1, double ground_height, double known_gap) {
  PathReach r;
  r.bodies = s.bodies;
  if (s.kind != StencilKind::PointGround) {
    if (std::isnan(known_gap)) {
      const StencilGeometry g = stencil_geometry(s, x0, ground_height, 0);
      known_gap = g.infeasible ? 0.0 : std::sqrt(g.d2) - s.xi;
    }
    if (!(known_gap > 0.0)) {  // within the thickness already: always in the active set
      r.gap0 = -std::numeric_limits<double>::infinity();
      return r;
    }
  }
  double size = 0.0;  // coordinate magnitude, for the absolute rounding allowance
  if (s.kind == StencilKind::PointGround) {
    const Vec3& p = x0[s.vertices[0]];
    r.gap0 = p.z() - ground_height - s.xi;
    r.move_a = std::abs(p1[0].z() - p.z());
    size = std::max(std::abs(p.z()), std::abs(ground_height)) + r.move_a;
  } else {
    r.gap0 = known_gap;
    const int n_first = s.kind == StencilKind::PointTriangle ? 1 : 2;
    std::array<Vec3, 4> dx;
    Vec3 c = Vec3::Zero();
    for (int i = 0; i < 4; ++i) c += (dx[i] = p1[i] - x0[s.vertices[i]]);
    c /= 4.0;
    for (int i = 0; i < 4; ++i) {
      double& m = i < n_first ? r.move_a : r.move_b;
      m = std::max(m, (dx[i] - c).norm());
      size = std::max(size, x0[s.vertices[i]].cwiseAbs().maxCoeff());
    }
    r.common = c.norm();
    size += r.move_a + r.move_b + r.common;
  }
  r.slack = kAbsoluteSlack * size;
  return r;
}

PathReach path_reach_from_ccd(const ContactStencil& s, const std::vector<Vec3>& x0, double gap0,
                              double move_a, double move_b, double common) {
  PathReach r;
  r.bodies = s.bodies;
  if (!(gap0 > 0.0)) {  // within the thickness already: always in the active set
    r.gap0 = -std::numeric_limits<double>::infinity();
    return r;
  }
  r.gap0 = gap0;
  r.move_a = move_a;
  r.move_b = move_b;
  r.common = common;
  double size = 0.0;
  for (int i = 0; i < 4; ++i) size = std::max(size, x0[s.vertices[i]].cwiseAbs().maxCoeff());
  size += r.move_a + r.move_b + r.common;
  r.slack = kAbsoluteSlack * size;
  return r;
}

void reachable_candidates(const Candidates& all, const std::vector<PathReach>& reach_of,
                          const std::vector<double>& t, double reach, Candidates& out) {
  out.point_triangle.clear();
  out.edge_edge.clear();
  out.point_ground.clear();
  out.edge_triangle.clear();
  out.overflow = false;
  const double limit = (1.0 + kRelativeSlack) * reach;
  auto near = [&](size_t i) {
    const PathReach& r = reach_of[i];
    const double ta = t[size_t(r.bodies[0])];
    const double tb = r.bodies[1] >= 0 ? t[size_t(r.bodies[1])] : 0.0;
    return lowest_gap(r, ta, tb) < limit;
  };
  size_t i = 0;
  for (const auto& pt : all.point_triangle)
    if (near(i++)) out.point_triangle.push_back(pt);
  for (const auto& ee : all.edge_edge)
    if (near(i++)) out.edge_edge.push_back(ee);
  for (int v : all.point_ground)
    if (near(i++)) out.point_ground.push_back(v);
}

}  // namespace abd::contact
