// Which pair of closest features realises the distance between two primitives. Every
// primitive-pair distance is piecewise smooth; the type names the smooth piece. Names and
// integer values follow IPC's convention (as ipctk spells them) so tests compare 1:1.
#pragma once
#include "common/types.h"

namespace abd::contact {

enum class PointEdgeDistanceType : int { P_E0 = 0, P_E1 = 1, P_E = 2, AUTO = 3 };

// P_Ek: the point is closest to edge k of the triangle, edges (t0,t1), (t1,t2), (t2,t0).
enum class PointTriangleDistanceType : int {
  P_T0 = 0, P_T1 = 1, P_T2 = 2, P_E0 = 3, P_E1 = 4, P_E2 = 5, P_T = 6, AUTO = 7
};

// EA_EB0: the interior of edge a is closest to vertex eb0, and so on.
enum class EdgeEdgeDistanceType : int {
  EA0_EB0 = 0, EA0_EB1 = 1, EA1_EB0 = 2, EA1_EB1 = 3,
  EA_EB0 = 4, EA_EB1 = 5, EA0_EB = 6, EA1_EB = 7, EA_EB = 8, AUTO = 9
};

PointEdgeDistanceType point_edge_distance_type(const Vec3& p, const Vec3& e0, const Vec3& e1);

PointTriangleDistanceType point_triangle_distance_type(const Vec3& p, const Vec3& t0,
                                                       const Vec3& t1, const Vec3& t2);

// Near-parallel edges (|ea × eb|² below 1e-20 |ea|²|eb|²) never get EA_EB: the line–line
// distance is ill-conditioned there, and a point–edge piece gives the same value.
EdgeEdgeDistanceType edge_edge_distance_type(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                             const Vec3& eb1);

}  // namespace abd::contact
