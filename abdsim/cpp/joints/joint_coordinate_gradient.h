// A 1-dof joint's coordinate θ(q) as a smooth function of the two bodies' states, with its
// gradient, for the joint energies (joints/joint_force_term.h):
//   revolute  θ = atan2(w·(u_p × u_c), u_p·u_c), w = A_p t̄, u_p = A_p n̄_p, u_c = A_c n̄_c
//             (in (−π, π]; the caller unwraps). Equal to the reported hinge angle for rigid
//             bodies; polynomial pieces, so the gradient is exact.
//   prismatic θ = w·(x_c − x_p) at the anchor.
// Gradients are ∂θ/∂q_child and ∂θ/∂q_parent (zero for the world).
#pragma once
#include "joints/joint_spec.h"

namespace abd {

double joint_coordinate(const JointFrame& f, const VecX& q, Vec12* grad_child,
                        Vec12* grad_parent);

}  // namespace abd
