#include "contact/intersection/segment_triangle.h"

namespace abd::contact {

bool segment_triangle_intersect(const Vec3& a, const Vec3& b, const Vec3& t0, const Vec3& t1,
                                const Vec3& t2) {
  const Vec3 n = (t1 - t0).cross(t2 - t0);
  const double da = (a - t0).dot(n), db = (b - t0).dot(n);
  if ((da > 0.0 && db > 0.0) || (da < 0.0 && db < 0.0) || da == db) return false;
  const Vec3 x = a + (da / (da - db)) * (b - a);  // where the segment meets the plane
  // Inside iff x is on the inner side of all three edges (w.r.t. the triangle's normal).
  return (t1 - t0).cross(x - t0).dot(n) >= 0.0 && (t2 - t1).cross(x - t1).dot(n) >= 0.0 &&
         (t0 - t2).cross(x - t2).dot(n) >= 0.0;
}

}  // namespace abd::contact
