// Tangent bases for lagged friction: an orthonormal 3×2 basis T of the plane orthogonal to
// the contact normal. Only the plane matters (D depends on |Tᵀ v|), so the first column is
// chosen deterministically: the part of a "preferred" direction (an edge of the pair) that
// is orthogonal to the normal. Same planes as ipctk's *_tangent_basis.
#pragma once
#include "contact/stencil_types.h"

namespace abd::contact {

Mat3x2 tangent_basis(const Vec3& normal, const Vec3& preferred);

Mat3x2 point_point_tangent_basis(const Vec3& p0, const Vec3& p1);
Mat3x2 point_edge_tangent_basis(const Vec3& p, const Vec3& e0, const Vec3& e1);
Mat3x2 point_triangle_tangent_basis(const Vec3& p, const Vec3& t0, const Vec3& t1,
                                    const Vec3& t2);
Mat3x2 edge_edge_tangent_basis(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                               const Vec3& eb1);

}  // namespace abd::contact
