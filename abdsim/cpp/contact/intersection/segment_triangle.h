// Does a segment cross a triangle? Used only to validate an initial configuration: an edge
// that pierces a triangle makes two surfaces intersect although no point–triangle or
// edge–edge distance need be zero. Floating-point orientation tests, no exact predicates:
// a segment lying in the triangle's plane is reported as not crossing, because such a
// configuration has a zero point–triangle/edge–edge distance and is caught by the distance
// check instead.
#pragma once
#include "common/types.h"

namespace abd::contact {

bool segment_triangle_intersect(const Vec3& a, const Vec3& b, const Vec3& t0, const Vec3& t1,
                                const Vec3& t2);

}  // namespace abd::contact
