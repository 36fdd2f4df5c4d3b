// Closest-point parameters of the smooth distance pieces (unclamped, i.e. of the lines and
// planes; the distance type says when they are the segment's/triangle's own). Friction uses
// them, as the weights w of affine_distance.h, to measure the relative sliding of the two
// closest points.
#pragma once
#include "common/types.h"

namespace abd::contact {

// s with p's projection e0 + s (e1 − e0).
double point_edge_closest_point(const Vec3& p, const Vec3& e0, const Vec3& e1);
// (β1, β2) with p's projection t0 + β1 (t1 − t0) + β2 (t2 − t0).
Eigen::Vector2d point_triangle_closest_point(const Vec3& p, const Vec3& t0, const Vec3& t1,
                                             const Vec3& t2);
// (s, t): closest points ea0 + s (ea1 − ea0) and eb0 + t (eb1 − eb0) of the two lines.
Eigen::Vector2d edge_edge_closest_point(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                        const Vec3& eb1);

}  // namespace abd::contact
