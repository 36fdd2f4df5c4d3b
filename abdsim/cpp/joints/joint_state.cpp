#include "joints/joint_state.h"

#include <Eigen/SVD>

namespace abd {

Mat3 nearest_rotation(const Mat3& A) {
  const Eigen::JacobiSVD<Mat3> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 U = svd.matrixU();
  const Mat3 V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0.0) U.col(2) *= -1.0;
  return U * V.transpose();
}

Vec3 angular_velocity(const Mat3& A, const Mat3& A_dot) {
  const Mat3 W = A_dot * A.inverse();
  return 0.5 * Vec3(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
}

Eigen::Vector4d quaternion_wxyz(const Mat3& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() *= -1.0;  // one of ±q: the one with w >= 0
  return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
}

}  // namespace abd
