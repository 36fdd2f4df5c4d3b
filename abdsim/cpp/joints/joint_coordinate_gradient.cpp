#include "joints/joint_coordinate_gradient.h"

#include <cmath>

#include "joints/joint_state.h"

namespace abd {

double joint_coordinate(const JointFrame& f, const VecX& q, Vec12* grad_child,
                        Vec12* grad_parent) {
  const Vec12 qp = body_q(q, f.spec.parent), qc = body_q(q, f.spec.child);
  const Mat3 Ap = affine_A(qp), Ac = affine_A(qc);
  const Vec3 w = Ap * f.axis_p;
  Vec12 gc = Vec12::Zero(), gp = Vec12::Zero();
  // The value alone (line-search trials, diagnostics) skips the gradient's arithmetic.
  const bool gradient = grad_child || grad_parent;
  double theta = 0.0;
  if (f.spec.kind == JointKind::kPrismatic) {
    const Vec3 d = affine_point(qc, f.anchor_c) - affine_point(qp, f.anchor_p);
    theta = w.dot(d);
    for (int i = 0; i < 3 && gradient; ++i) {
      gc[i] = w[i];
      gc.segment<3>(3 + 3 * i) = w[i] * f.anchor_c;
      gp[i] = -w[i];
      gp.segment<3>(3 + 3 * i) = -w[i] * f.anchor_p + d[i] * f.axis_p;
    }
  } else {
    const Vec3 up = Ap * f.normal_p, uc = Ac * f.normal_c;
    const double s = w.dot(up.cross(uc)), c = up.dot(uc);
    theta = std::atan2(s, c);
    if (!gradient) return theta;
    const double r2 = s * s + c * c;
    // ∂s/∂w = u_p × u_c, ∂s/∂u_p = u_c × w, ∂s/∂u_c = w × u_p; ∂c/∂u_p = u_c, ∂c/∂u_c = u_p;
    // (A v̄)_i depends on row a_i only, through v̄.
    const Vec3 s_w = up.cross(uc), s_up = uc.cross(w), s_uc = w.cross(up);
    for (int i = 0; i < 3; ++i) {
      const Vec3 ds_p = s_w[i] * f.axis_p + s_up[i] * f.normal_p;
      const Vec3 dc_p = uc[i] * f.normal_p;
      const Vec3 ds_c = s_uc[i] * f.normal_c;
      const Vec3 dc_c = up[i] * f.normal_c;
      gp.segment<3>(3 + 3 * i) = (c * ds_p - s * dc_p) / r2;
      gc.segment<3>(3 + 3 * i) = (c * ds_c - s * dc_c) / r2;
    }
  }
  if (grad_child) *grad_child = gc;
  if (grad_parent) *grad_parent = f.spec.parent >= 0 ? gp : Vec12::Zero();
  return theta;
}

}  // namespace abd
