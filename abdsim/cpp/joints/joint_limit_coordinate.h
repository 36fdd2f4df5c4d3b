// A 1-dof joint's coordinate θ(q) as a smooth function of the two bodies' states, with its
// gradient and Hessian, for the joint energies and the limit barrier's step bound
// (joints/joint_force_term.h):
//   revolute  the angle of the child's normal seen in the PARENT's own frame: with
//             v = A_p⁻¹ A_c n̄_c (the child's joint normal carried back through the parent's
//             current affine map), θ = atan2(b̄·v, n̄_p·v), n̄_p the parent's joint normal and
//             b̄ = t̄ × n̄_p (normal2_p), both in the parent's rest frame. This is the hinge's
//             joint_positions() angle for rigid bodies (whatever the parent's pose); measured
//             in world axes instead, a turned or sheared parent changes the angle the barrier
//             sees from the one the limits are given in.
//   prismatic θ = w·(x_c − x_p) at the anchor, w = A_p t̄.
// The revolute value lies in (−π, π]; the caller unwraps. The Hessian is the exact one of
// θ(q) (indefinite: a barrier E(θ) adds E'(θ) ∇²θ to its Gauss–Newton E'' ∇θ∇θᵀ and projects).
#pragma once
#include "joints/joint_spec.h"

namespace abd {

// ∇²θ over [q_child (12); q_parent (12)] (the parent's half zero for the world).
using Mat24 = Eigen::Matrix<double, 24, 24>;

// θ at q; gradients ∂θ/∂q_child and ∂θ/∂q_parent and the Hessian where non-null.
double joint_limit_coordinate(const JointFrame& f, const VecX& q, Vec12* grad_child,
                              Vec12* grad_parent, Mat24* hessian = nullptr);

}  // namespace abd
