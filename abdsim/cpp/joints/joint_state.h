// Rigid-body readings of affine body states for the joints: the world as a body, the
// rotation nearest to A, the angular velocity of Ȧ, and quaternions.
#pragma once
#include <Eigen/Geometry>

#include "common/affine.h"
#include "common/types.h"

namespace abd {

// q of body b; the world (b < 0) is the identity A = I, p = 0.
inline Vec12 body_q(const VecX& q, int b) {
  if (b < 0) return q_from(Mat3::Identity(), Vec3::Zero());
  return q.segment<12>(12 * b);
}
inline Vec12 body_q_dot(const VecX& q_dot, int b) {
  if (b < 0) return Vec12::Zero();
  return q_dot.segment<12>(12 * b);
}

// The rotation of A's polar decomposition (A is only near-rotational).
Mat3 nearest_rotation(const Mat3& A);
// ω with [ω]× the skew part of Ȧ A⁻¹ (exact for a rigid motion Ȧ = [ω]× A).
Vec3 angular_velocity(const Mat3& A, const Mat3& A_dot);
// w-first unit quaternion of a rotation matrix.
Eigen::Vector4d quaternion_wxyz(const Mat3& R);

}  // namespace abd
