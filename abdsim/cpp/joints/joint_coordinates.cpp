#include "joints/joint_coordinates.h"

#include <algorithm>
#include <cmath>

#include "joints/joint_limit_coordinate.h"
#include "joints/joint_state.h"

namespace abd {
namespace {

Vec3 world_axis(const JointFrame& f, const Vec12& qp) {
  return (affine_A(qp) * f.axis_p).normalized();
}

}  // namespace

// One definition of the 1-dof coordinates: the limits' and joint energies' own
// (joints/joint_limit_coordinate.h), so joint_positions() reads what the barrier holds.
double hinge_angle(const JointFrame& f, const VecX& q) {
  return joint_limit_coordinate(f, q, nullptr, nullptr);
}

void joint_position(const JointFrame& f, const VecX& q, double* out) {
  const Vec12 qp = body_q(q, f.spec.parent), qc = body_q(q, f.spec.child);
  switch (f.spec.kind) {
    case JointKind::kRevolute:
    case JointKind::kPrismatic:
      out[0] = joint_limit_coordinate(f, q, nullptr, nullptr);
      break;
    case JointKind::kBall: {
      const Mat3 rel = nearest_rotation(affine_A(qp)).transpose() * nearest_rotation(affine_A(qc));
      const Eigen::Vector4d quat = quaternion_wxyz(f.rel0.transpose() * rel);
      for (int i = 0; i < 4; ++i) out[i] = quat[i];
      break;
    }
    case JointKind::kFree: {
      const Eigen::Vector4d quat = quaternion_wxyz(nearest_rotation(affine_A(qc)));
      for (int i = 0; i < 3; ++i) out[i] = qc[i];
      for (int i = 0; i < 4; ++i) out[3 + i] = quat[i];
      break;
    }
    case JointKind::kFixed:
      break;
  }
}

void joint_velocity(const JointFrame& f, const VecX& q, const VecX& q_dot, double* out) {
  const Vec12 qp = body_q(q, f.spec.parent), qc = body_q(q, f.spec.child);
  const Vec12 vp = body_q_dot(q_dot, f.spec.parent), vc = body_q_dot(q_dot, f.spec.child);
  const Vec3 wp = angular_velocity(affine_A(qp), affine_A(vp));
  const Vec3 wc = angular_velocity(affine_A(qc), affine_A(vc));
  switch (f.spec.kind) {
    case JointKind::kRevolute:
      out[0] = world_axis(f, qp).dot(wc - wp);
      break;
    case JointKind::kPrismatic: {
      // Rates of the two anchor points (ẋ = Ȧ x̄ + ṗ); the axis turns ⊥ the offset.
      const Vec3 rate = affine_point(vc, f.anchor_c) - affine_point(vp, f.anchor_p);
      out[0] = world_axis(f, qp).dot(rate);
      break;
    }
    case JointKind::kBall: {
      const Vec3 local = nearest_rotation(affine_A(qc)).transpose() * (wc - wp);
      for (int i = 0; i < 3; ++i) out[i] = local[i];
      break;
    }
    case JointKind::kFree: {
      const Vec3 local = nearest_rotation(affine_A(qc)).transpose() * wc;
      for (int i = 0; i < 3; ++i) out[i] = vc[i];
      for (int i = 0; i < 3; ++i) out[3 + i] = local[i];
      break;
    }
    case JointKind::kFixed:
      break;
  }
}

ConstraintViolation joint_violation(const JointFrame& f, const VecX& q) {
  WorstViolation worst;
  add_joint_violation(f, q, worst);
  return worst.result();
}

void add_joint_violation(const JointFrame& f, const VecX& q, WorstViolation& worst) {
  if (f.spec.kind == JointKind::kFree) return;
  const Vec12 qp = body_q(q, f.spec.parent), qc = body_q(q, f.spec.child);
  const Mat3 Ap = affine_A(qp), Ac = affine_A(qc);
  const Vec3 gap = affine_point(qc, f.anchor_c) - affine_point(qp, f.anchor_p);
  switch (f.spec.kind) {
    case JointKind::kBall:
      worst.add_distance_squared(gap.squaredNorm());
      break;
    case JointKind::kRevolute: {
      worst.add_distance_squared(gap.squaredNorm());
      const Vec3 axis_c = affine_point(qc, f.tip_c) - affine_point(qc, f.anchor_c);
      const Vec3 axis_p = affine_point(qp, f.tip_p) - affine_point(qp, f.anchor_p);
      worst.add_angle(axis_c, axis_p);
      break;
    }
    case JointKind::kFixed:
    case JointKind::kPrismatic: {
      if (f.spec.kind == JointKind::kFixed) {
        worst.add_distance_squared(gap.squaredNorm());
      } else {
        const Vec3 w = world_axis(f, qp);
        worst.add_distance_squared((gap - gap.dot(w) * w).squaredNorm());
      }
      for (int j = 0; j < 3; ++j) worst.add_angle(Ac * f.basis_c.col(j), Ap * f.basis_p.col(j));
      break;
    }
    case JointKind::kFree:
      break;
  }
}

}  // namespace abd
