// Each distance type is one smooth piece: a stencil over some of the pair's vertices. The
// tables are indexed by the type's integer value (distance_types.h).
#include "contact/distance/distance.h"


namespace abd::contact {
namespace {
using stencil::Piece;
constexpr auto PP = stencil::PieceKind::PointPoint;
constexpr auto PL = stencil::PieceKind::PointLine;

// P_E0 P_E1 | P_E
constexpr Piece kPointEdge[] = {{PP, {0, 1}}, {PP, {0, 2}}, {PL, {0, 1, 2}}};
// P_T0 P_T1 P_T2 | P_E0 P_E1 P_E2 | P_T
constexpr Piece kPointTriangle[] = {
    {PP, {0, 1}}, {PP, {0, 2}}, {PP, {0, 3}}, {PL, {0, 1, 2}}, {PL, {0, 2, 3}}, {PL, {0, 3, 1}},
    {stencil::PieceKind::PointPlane, {0, 1, 2, 3}}};
// EA0_EB0 EA0_EB1 EA1_EB0 EA1_EB1 | EA_EB0 EA_EB1 EA0_EB EA1_EB | EA_EB
constexpr Piece kEdgeEdge[] = {
    {PP, {0, 2}}, {PP, {0, 3}}, {PP, {1, 2}}, {PP, {1, 3}}, {PL, {2, 0, 1}}, {PL, {3, 0, 1}},
    {PL, {0, 2, 3}}, {PL, {1, 2, 3}}, {stencil::PieceKind::LineLine, {0, 1, 2, 3}}};
}  // namespace

const Piece& point_edge_piece(PointEdgeDistanceType type) { return kPointEdge[int(type)]; }
const Piece& point_triangle_piece(PointTriangleDistanceType type) {
  return kPointTriangle[int(type)];
}
const Piece& edge_edge_piece(EdgeEdgeDistanceType type) { return kEdgeEdge[int(type)]; }

AffineDistance<2> point_point_distance_derivatives(const Vec3& p0, const Vec3& p1, int order) {
  return stencil::point_point<2>({p0, p1}, {0, 1}, order);
}

AffineDistance<3> point_edge_distance_derivatives(const Vec3& p, const Vec3& e0, const Vec3& e1,
                                                  PointEdgeDistanceType type, int order) {
  if (type == PointEdgeDistanceType::AUTO) type = point_edge_distance_type(p, e0, e1);
  return stencil::evaluate_piece<3>({p, e0, e1}, point_edge_piece(type), order);
}

AffineDistance<4> point_triangle_distance_derivatives(const Vec3& p, const Vec3& t0,
                                                      const Vec3& t1, const Vec3& t2,
                                                      PointTriangleDistanceType type, int order) {
  if (type == PointTriangleDistanceType::AUTO) type = point_triangle_distance_type(p, t0, t1, t2);
  return stencil::evaluate_piece<4>({p, t0, t1, t2}, point_triangle_piece(type), order);
}

AffineDistance<4> edge_edge_distance_derivatives(const Vec3& ea0, const Vec3& ea1,
                                                 const Vec3& eb0, const Vec3& eb1,
                                                 EdgeEdgeDistanceType type, int order) {
  if (type == EdgeEdgeDistanceType::AUTO) type = edge_edge_distance_type(ea0, ea1, eb0, eb1);
  return stencil::evaluate_piece<4>({ea0, ea1, eb0, eb1}, edge_edge_piece(type), order);
}

double point_edge_distance(const Vec3& p, const Vec3& e0, const Vec3& e1) {
  return point_edge_distance_derivatives(p, e0, e1, PointEdgeDistanceType::AUTO, 0).d2;
}

double point_triangle_distance(const Vec3& p, const Vec3& t0, const Vec3& t1, const Vec3& t2) {
  return point_triangle_distance_derivatives(p, t0, t1, t2, PointTriangleDistanceType::AUTO, 0).d2;
}

double edge_edge_distance(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0, const Vec3& eb1) {
  return edge_edge_distance_derivatives(ea0, ea1, eb0, eb1, EdgeEdgeDistanceType::AUTO, 0).d2;
}

}  // namespace abd::contact
