// Joint coordinates in MuJoCo's conventions, relative to the configuration at load:
//   revolute  qpos: the angle θ of the child about the axis, relative to the parent (right-
//             handed about the parent's axis); qvel: (ω_c − ω_p)·axis
//   prismatic qpos: (x_c − x_p)·axis at the anchor; qvel: its rate
//   ball      qpos: w-first quaternion of R_rel₀ᵀ R_rel with R_rel = R_pᵀ R_c (rotations
//             nearest to A); qvel: R_cᵀ (ω_c − ω_p), in the child's frame
//   free      qpos: p and the quaternion of R_c; qvel: ṗ (world) and R_cᵀ ω_c (body frame)
//   fixed     nothing.
// Hinge and slide coordinates are joint_limit_coordinate's (the angle read in the parent's
// own frame). The hinge angle here lies in (−π, π]; JointSet unwraps it from step to step.
#pragma once
#include "joints/joint_spec.h"
#include "joints/worst_violation.h"
#include "solver/constraint.h"

namespace abd {

double hinge_angle(const JointFrame& f, const VecX& q);
// joint_nq(kind) values into out (revolute: the angle in (−π, π]).
void joint_position(const JointFrame& f, const VecX& q, double* out);
// joint_nv(kind) values into out.
void joint_velocity(const JointFrame& f, const VecX& q, const VecX& q_dot, double* out);
// Anchor separation (prismatic: the offset across the axis), m; axis or frame misalignment,
// rad.
ConstraintViolation joint_violation(const JointFrame& f, const VecX& q);
// The same, folded into the worst over a set of joints.
void add_joint_violation(const JointFrame& f, const VecX& q, WorstViolation& worst);

}  // namespace abd
