// Classification by convexity: the squared distance is a convex quadratic in the barycentric
// parameters over a convex domain (segment, triangle, square of two segments). If the
// unconstrained minimiser lies inside the domain it is the answer (the interior piece);
// otherwise the minimum lies on the domain's boundary, i.e. it is a point–segment distance,
// and we take the best boundary candidate. Ties (equal distances) go to the first candidate,
// which is harmless: the tied pieces have equal values there.
#include "contact/distance/distance_types.h"

#include <algorithm>
#include <array>
#include <limits>

namespace abd::contact {
namespace {

struct SegmentHit {
  double d2;
  double s;  // clamped to [0, 1]
};

SegmentHit point_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 e = b - a;
  const double ee = e.squaredNorm();
  const double s = ee > 0.0 ? std::clamp((p - a).dot(e) / ee, 0.0, 1.0) : 0.0;
  return {(p - a - s * e).squaredNorm(), s};
}

// Which of {endpoint a, interior, endpoint b} a clamped segment parameter names.
int segment_feature(double s) { return s <= 0.0 ? 0 : (s >= 1.0 ? 2 : 1); }

constexpr double kParallelTolerance = 1e-20;

}  // namespace

PointEdgeDistanceType point_edge_distance_type(const Vec3& p, const Vec3& e0, const Vec3& e1) {
  const Vec3 e = e1 - e0;
  const double s = (p - e0).dot(e) / e.squaredNorm();
  if (s < 0.0) return PointEdgeDistanceType::P_E0;
  if (s > 1.0) return PointEdgeDistanceType::P_E1;
  return PointEdgeDistanceType::P_E;
}

PointTriangleDistanceType point_triangle_distance_type(const Vec3& p, const Vec3& t0,
                                                       const Vec3& t1, const Vec3& t2) {
  using T = PointTriangleDistanceType;
  const Vec3 e0 = t1 - t0, e1 = t2 - t0, d = p - t0;
  const double det = e0.cross(e1).squaredNorm();
  if (det > 0.0) {
    // Barycentric coordinates of p's projection onto the triangle's plane.
    const double e00 = e0.dot(e0), e01 = e0.dot(e1), e11 = e1.dot(e1);
    const double d0 = e0.dot(d), d1 = e1.dot(d);
    const double b1 = (e11 * d0 - e01 * d1) / det;
    const double b2 = (e00 * d1 - e01 * d0) / det;
    if (b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0) return T::P_T;
  }
  const std::array<Vec3, 3> t{t0, t1, t2};
  // Edge k runs from vertex k to vertex (k+1) % 3: feature 0 -> P_Tk, 1 -> P_Ek, 2 -> P_T(k+1).
  T best = T::P_T0;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const SegmentHit hit = point_segment(p, t[k], t[(k + 1) % 3]);
    if (hit.d2 < best_d2) {
      best_d2 = hit.d2;
      const int f = segment_feature(hit.s);
      best = f == 1 ? T(int(T::P_E0) + k) : T(f == 0 ? k : (k + 1) % 3);
    }
  }
  return best;
}

EdgeEdgeDistanceType edge_edge_distance_type(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                             const Vec3& eb1) {
  using T = EdgeEdgeDistanceType;
  const Vec3 ea = ea1 - ea0, eb = eb1 - eb0, w0 = ea0 - eb0;
  const double a = ea.dot(ea), b = ea.dot(eb), c = eb.dot(eb);
  const double det = ea.cross(eb).squaredNorm();
  if (det > kParallelTolerance * a * c) {
    // Stationary point of |w0 + s ea − t eb|².
    const double d = ea.dot(w0), e = eb.dot(w0);
    const double s = (b * e - c * d) / det;
    const double t = (a * e - b * d) / det;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) return T::EA_EB;
  }
  // Boundary of the parameter square: an endpoint of one edge against the other segment.
  // Type tables indexed by segment feature {endpoint 0, interior, endpoint 1} of the segment.
  struct Candidate {
    SegmentHit hit;
    std::array<T, 3> types;
  };
  const std::array<Candidate, 4> candidates{{
      {point_segment(ea0, eb0, eb1), {T::EA0_EB0, T::EA0_EB, T::EA0_EB1}},
      {point_segment(ea1, eb0, eb1), {T::EA1_EB0, T::EA1_EB, T::EA1_EB1}},
      {point_segment(eb0, ea0, ea1), {T::EA0_EB0, T::EA_EB0, T::EA1_EB0}},
      {point_segment(eb1, ea0, ea1), {T::EA0_EB1, T::EA_EB1, T::EA1_EB1}},
  }};
  const Candidate* best = &candidates[0];
  for (const Candidate& cand : candidates)
    if (cand.hit.d2 < best->hit.d2) best = &cand;
  return best->types[segment_feature(best->hit.s)];
}

}  // namespace abd::contact
