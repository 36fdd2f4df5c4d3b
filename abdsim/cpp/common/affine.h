// Affine-body kinematics (ABD_NOTES §1): q = [p; a1; a2; a3], a_i the ROWS of A,
// a material point moves as x = A x̄ + p = J(x̄) q.
#pragma once
#include "common/types.h"

namespace abd {

// A from q (rows a1, a2, a3 stored consecutively after p).
inline Mat3 affine_A(const Vec12& q) {
  Mat3 A;
  A.row(0) = q.segment<3>(3).transpose();
  A.row(1) = q.segment<3>(6).transpose();
  A.row(2) = q.segment<3>(9).transpose();
  return A;
}

inline Vec3 affine_p(const Vec12& q) { return q.head<3>(); }

inline Vec12 q_from(const Mat3& A, const Vec3& p) {
  Vec12 q;
  q.head<3>() = p;
  q.segment<3>(3) = A.row(0).transpose();
  q.segment<3>(6) = A.row(1).transpose();
  q.segment<3>(9) = A.row(2).transpose();
  return q;
}

// x = A x̄ + p
inline Vec3 affine_point(const Vec12& q, const Vec3& x_bar) {
  return Vec3(q.segment<3>(3).dot(x_bar) + q[0], q.segment<3>(6).dot(x_bar) + q[1],
              q.segment<3>(9).dot(x_bar) + q[2]);
}

// J(x̄), 3x12, as in the spec.
inline Mat3x12 affine_jacobian(const Vec3& x_bar) {
  Mat3x12 J = Mat3x12::Zero();
  J.block<3, 3>(0, 0).setIdentity();
  J.block<1, 3>(0, 3) = x_bar.transpose();
  J.block<1, 3>(1, 6) = x_bar.transpose();
  J.block<1, 3>(2, 9) = x_bar.transpose();
  return J;
}

}  // namespace abd
