// The parameters are read off the affine stencils' optimal weights (affine_distance.h), so
// they are, by construction, the same points the distance and its gradient use.
#include "contact/friction/closest_point.h"

#include "contact/distance/stencils.h"

namespace abd::contact {

double point_edge_closest_point(const Vec3& p, const Vec3& e0, const Vec3& e1) {
  // w = [1, −(1 − s), −s]
  return -stencil::point_line<3>({p, e0, e1}, {0, 1, 2}, 0).w[2];
}

Eigen::Vector2d point_triangle_closest_point(const Vec3& p, const Vec3& t0, const Vec3& t1,
                                             const Vec3& t2) {
  // w = [1, −(1 − β1 − β2), −β1, −β2]
  const auto w = stencil::point_plane<4>({p, t0, t1, t2}, {0, 1, 2, 3}, 0).w;
  return Eigen::Vector2d(-w[2], -w[3]);
}

Eigen::Vector2d edge_edge_closest_point(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                        const Vec3& eb1) {
  // w = [1 − s, s, −(1 − t), −t]
  const auto w = stencil::line_line<4>({ea0, ea1, eb0, eb1}, {0, 1, 2, 3}, 0).w;
  return Eigen::Vector2d(w[1], -w[3]);
}

}  // namespace abd::contact
