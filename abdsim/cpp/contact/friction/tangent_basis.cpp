#include "contact/friction/tangent_basis.h"

namespace abd::contact {
namespace {

// The coordinate axis least aligned with v: never (nearly) parallel to it.
Vec3 least_aligned_axis(const Vec3& v) {
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(v[i]) < std::abs(v[k])) k = i;
  return Vec3::Unit(k);
}

}  // namespace

Mat3x2 tangent_basis(const Vec3& normal, const Vec3& preferred) {
  // A zero normal (touching primitives) leaves the plane undefined; any plane containing
  // `preferred` is then as good as another.
  Vec3 n = normal;
  if (n.squaredNorm() == 0.0) n = preferred.cross(least_aligned_axis(preferred));
  n.normalize();
  Vec3 t1 = preferred - preferred.dot(n) * n;
  if (t1.squaredNorm() <= 1e-24 * preferred.squaredNorm() || preferred.squaredNorm() == 0.0) {
    const Vec3 axis = least_aligned_axis(n);
    t1 = axis - axis.dot(n) * n;
  }
  t1.normalize();
  Mat3x2 T;
  T.col(0) = t1;
  T.col(1) = n.cross(t1);
  return T;
}

Mat3x2 point_point_tangent_basis(const Vec3& p0, const Vec3& p1) {
  const Vec3 n = p0 - p1;
  return tangent_basis(n, least_aligned_axis(n));
}

Mat3x2 point_edge_tangent_basis(const Vec3& p, const Vec3& e0, const Vec3& e1) {
  const Vec3 e = e1 - e0;
  const Vec3 d = p - e0;
  return tangent_basis(d - (d.dot(e) / e.squaredNorm()) * e, e);
}

Mat3x2 point_triangle_tangent_basis(const Vec3& /*p*/, const Vec3& t0, const Vec3& t1,
                                    const Vec3& t2) {
  return tangent_basis((t1 - t0).cross(t2 - t0), t1 - t0);
}

Mat3x2 edge_edge_tangent_basis(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                               const Vec3& eb1) {
  const Vec3 ea = ea1 - ea0;
  return tangent_basis(ea.cross(eb1 - eb0), ea);
}

}  // namespace abd::contact
