// Typed squared distances between primitive pairs, with gradients and Hessians w.r.t. the
// stacked vertex coordinates ([p; e0; e1], [p; t0; t1; t2], [ea0; ea1; eb0; eb1]).
// `type` picks the smooth piece (distance_types.h); AUTO classifies first (the usual call), an
// explicit type evaluates that piece everywhere (tests, lagged classification).
// order: 0 value (+ closest-point weights), 1 + gradient, 2 + Hessian.
// Edge–edge is not mollified here: see edge_edge_mollifier.h.
#pragma once
#include "contact/distance/affine_distance.h"
#include "contact/distance/distance_types.h"
#include "contact/distance/stencils.h"

namespace abd::contact {

AffineDistance<2> point_point_distance_derivatives(const Vec3& p0, const Vec3& p1, int order);

AffineDistance<3> point_edge_distance_derivatives(const Vec3& p, const Vec3& e0, const Vec3& e1,
                                                  PointEdgeDistanceType type, int order);

AffineDistance<4> point_triangle_distance_derivatives(const Vec3& p, const Vec3& t0,
                                                      const Vec3& t1, const Vec3& t2,
                                                      PointTriangleDistanceType type, int order);

AffineDistance<4> edge_edge_distance_derivatives(const Vec3& ea0, const Vec3& ea1,
                                                 const Vec3& eb0, const Vec3& eb1,
                                                 EdgeEdgeDistanceType type, int order);

// The smooth piece (stencil and vertex subset) that a distance type names.
const stencil::Piece& point_edge_piece(PointEdgeDistanceType type);
const stencil::Piece& point_triangle_piece(PointTriangleDistanceType type);
const stencil::Piece& edge_edge_piece(EdgeEdgeDistanceType type);

// Values only, classified automatically.
inline double point_point_distance(const Vec3& p0, const Vec3& p1) { return (p0 - p1).squaredNorm(); }
double point_edge_distance(const Vec3& p, const Vec3& e0, const Vec3& e1);
double point_triangle_distance(const Vec3& p, const Vec3& t0, const Vec3& t1, const Vec3& t2);
double edge_edge_distance(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0, const Vec3& eb1);

}  // namespace abd::contact
