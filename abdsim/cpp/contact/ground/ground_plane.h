// The ground: the half-space z ≥ h, handled analytically (no mesh, no broad phase beyond a
// height test). A vertex's distance to it is its height above the plane, z − h; the barrier
// takes its square like every other pair. Below the plane (z ≤ h) the pair is infeasible: the
// squared distance alone cannot tell "above" from "below", so callers check the sign.
#pragma once
#include "contact/ccd/additive_ccd.h"
#include "contact/stencil_types.h"

namespace abd::contact {

inline double point_ground_signed_distance(const Vec3& p, double height) { return p.z() - height; }

// (z − h)² and its derivatives w.r.t. p.
inline double point_ground_distance(const Vec3& p, double height) {
  const double s = p.z() - height;
  return s * s;
}
inline Vec3 point_ground_distance_gradient(const Vec3& p, double height) {
  return Vec3(0.0, 0.0, 2.0 * (p.z() - height));
}
inline Mat3 point_ground_distance_hessian() {
  Mat3 H = Mat3::Zero();
  H(2, 2) = 2.0;
  return H;
}

// The tangent plane of the ground: x and y.
inline Mat3x2 ground_tangent_basis() {
  Mat3x2 T = Mat3x2::Zero();
  T(0, 0) = 1.0;
  T(1, 1) = 1.0;
  return T;
}

// Exact CCD for a vertex moving linearly against the plane, made conservative like ACCD:
// returns the time at which the gap z − h − ξ has shrunk to `target` × its start value
// (tmax when the vertex does not reach the plane before tmax, 0 when it starts inside ξ).
double point_ground_ccd(const Vec3& p_t0, const Vec3& p_t1, double height,
                        const CcdOptions& options = {});

}  // namespace abd::contact
