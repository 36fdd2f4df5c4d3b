#include "contact/ccd/additive_ccd.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

#include "contact/distance/distance.h"

namespace abd::contact {
namespace {

// Vertices [0, n_first) belong to the first primitive, the rest to the second.
template <int NV, class SquaredDistance>
double additive_ccd(const std::array<Vec3, NV>& x0, const std::array<Vec3, NV>& x1, int n_first,
                    SquaredDistance squared_distance, const CcdOptions& o) {
  std::array<Vec3, NV> dx;
  Vec3 mean = Vec3::Zero();
  for (int i = 0; i < NV; ++i) mean += (dx[i] = x1[i] - x0[i]);
  mean /= double(NV);
  double la = 0.0, lb = 0.0;
  for (int i = 0; i < NV; ++i) {
    dx[i] -= mean;  // a common translation changes no distance
    double& l = i < n_first ? la : lb;
    l = std::max(l, dx[i].norm());
  }
  const double lp = la + lb;
  if (lp == 0.0) return o.tmax;

  const double xi = o.min_distance;
  // (d² − ξ²)/(d + ξ) = d − ξ, evaluated without forming d − ξ from two close numbers.
  auto gap_at = [&](double t) {
    std::array<Vec3, NV> y;
    for (int i = 0; i < NV; ++i) y[i] = x0[i] + t * dx[i];
    const double d2 = squared_distance(y);
    return (d2 - xi * xi) / (std::sqrt(d2) + xi);
  };

  const double gap0 = gap_at(0.0);
  if (o.start_gap) *o.start_gap = gap0;
  if (o.moves) *o.moves = {la, lb, mean.norm()};
  if (!(gap0 > 0.0)) return 0.0;
  const double g = o.target * gap0;
  double t = 0.0;
  double tl = (1.0 - o.target) * gap0 / lp;
  // A first step beyond tmax ends the loop below at tmax whatever the gap there (there is
  // no test at t = 0): no distance for it. Most swept pairs of a dense scene move far less
  // than their gap, so this halves their cost.
  if (o.max_iterations > 0 && tl > o.tmax) return o.tmax;
  for (long it = 0; it < o.max_iterations; ++it) {
    const double gap = gap_at(t + tl);
    if (t > 0.0 && gap < g) return t;
    t += tl;
    if (t > o.tmax) return o.tmax;
    tl = 0.9 * gap / lp;
  }
  return t;
}

// A squared-distance function of NV points, called on an array of them.
template <class F>
auto on_array(F f) {
  return [f](const auto& y) { return std::apply(f, y); };
}

}  // namespace

double point_point_ccd(const Vec3& p0_t0, const Vec3& p1_t0, const Vec3& p0_t1,
                       const Vec3& p1_t1, const CcdOptions& options) {
  return additive_ccd<2>({p0_t0, p1_t0}, {p0_t1, p1_t1}, 1, on_array(&point_point_distance), options);
}

double point_edge_ccd(const Vec3& p_t0, const Vec3& e0_t0, const Vec3& e1_t0, const Vec3& p_t1,
                      const Vec3& e0_t1, const Vec3& e1_t1, const CcdOptions& options) {
  return additive_ccd<3>({p_t0, e0_t0, e1_t0}, {p_t1, e0_t1, e1_t1}, 1,
                         on_array(&point_edge_distance), options);
}

double point_triangle_ccd(const Vec3& p_t0, const Vec3& t0_t0, const Vec3& t1_t0,
                          const Vec3& t2_t0, const Vec3& p_t1, const Vec3& t0_t1,
                          const Vec3& t1_t1, const Vec3& t2_t1, const CcdOptions& options) {
  return additive_ccd<4>({p_t0, t0_t0, t1_t0, t2_t0}, {p_t1, t0_t1, t1_t1, t2_t1}, 1,
                         on_array(&point_triangle_distance), options);
}

double edge_edge_ccd(const Vec3& ea0_t0, const Vec3& ea1_t0, const Vec3& eb0_t0,
                     const Vec3& eb1_t0, const Vec3& ea0_t1, const Vec3& ea1_t1,
                     const Vec3& eb0_t1, const Vec3& eb1_t1, const CcdOptions& options) {
  return additive_ccd<4>({ea0_t0, ea1_t0, eb0_t0, eb1_t0}, {ea0_t1, ea1_t1, eb0_t1, eb1_t1}, 2,
                         on_array(&edge_edge_distance), options);
}

}  // namespace abd::contact
