#include "joints/joint_limit_coordinate.h"

#include <cmath>

#include "joints/joint_state.h"

namespace abd {
namespace {

// Index of A_ij in a body's 12 state entries (q = [p; rows of A]).
constexpr int a_index(int i, int j) { return 3 + 3 * i + j; }

// s = ūᵀ A_p⁻¹ A_c n̄_c, one of the two bilinear readings of the revolute angle: its gradient
// (child, parent) and Hessian. With B = A_p⁻¹, u = Bᵀ ū, v = B A_c n̄_c:
//   ∂s/∂A_c,ij = u_i n̄_j,  ∂s/∂A_p,ij = −u_i v_j (from dB = −B dA_p B),
//   ∂²s/∂A_p,ij ∂A_c,kl = −u_i B_jk n̄_l,  ∂²s/∂A_p,ij ∂A_p,kl = u_i B_jk v_l + u_k B_li v_j.
void bilinear(const Vec3& u_bar, const Mat3& B, const Vec3& n_c, const Vec3& v, bool world,
              Vec12& gc, Vec12& gp, Mat24* H) {
  const Vec3 u = B.transpose() * u_bar;
  gc.setZero();
  gp.setZero();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      gc[a_index(i, j)] = u[i] * n_c[j];
      if (!world) gp[a_index(i, j)] = -u[i] * v[j];
    }
  if (!H) return;
  H->setZero();
  if (world) return;  // linear in the child alone
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int pij = 12 + a_index(i, j);
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) {
          const double cp = -u[i] * B(j, k) * n_c[l];
          (*H)(pij, a_index(k, l)) = cp;
          (*H)(a_index(k, l), pij) = cp;
          (*H)(pij, 12 + a_index(k, l)) = u[i] * B(j, k) * v[l] + u[k] * B(l, i) * v[j];
        }
    }
}

double revolute(const JointFrame& f, const Vec12& qp, const Vec12& qc, Vec12* gc_out,
                Vec12* gp_out, Mat24* H) {
  const bool world = f.spec.parent < 0;
  const Mat3 B = affine_A(qp).inverse();
  const Vec3 v = B * (affine_A(qc) * f.normal_c);
  const double x = f.normal_p.dot(v), y = f.normal2_p.dot(v);
  const double theta = std::atan2(y, x);
  if (!gc_out && !gp_out && !H) return theta;
  // θ = atan2(y, x): θ_x = −y/r², θ_y = x/r²; θ_xx = 2xy/r⁴ = −θ_yy, θ_xy = (y² − x²)/r⁴.
  const double r2 = x * x + y * y;
  const double tx = -y / r2, ty = x / r2;
  if (!H) {
    // The gradient alone (every Newton assembly and energy): the two readings' gradients
    // combine into one, ∂θ/∂A_c,ij = w_i n̄_j and ∂θ/∂A_p,ij = −w_i v_j with
    // w = Bᵀ(θ_x n̄_p + θ_y b̄), instead of building both and summing them.
    const Vec3 w = B.transpose() * (tx * f.normal_p + ty * f.normal2_p);
    for (Vec12* g : {gc_out, gp_out})
      if (g) g->setZero();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        if (gc_out) (*gc_out)[a_index(i, j)] = w[i] * f.normal_c[j];
        if (gp_out && !world) (*gp_out)[a_index(i, j)] = -w[i] * v[j];
      }
    return theta;
  }
  Vec12 gxc, gxp, gyc, gyp;
  Mat24 Hx, Hy;
  bilinear(f.normal_p, B, f.normal_c, v, world, gxc, gxp, &Hx);
  bilinear(f.normal2_p, B, f.normal_c, v, world, gyc, gyp, &Hy);
  if (gc_out) *gc_out = tx * gxc + ty * gyc;
  if (gp_out) *gp_out = tx * gxp + ty * gyp;
  Eigen::Matrix<double, 24, 1> gx, gy;
  gx << gxc, gxp;
  gy << gyc, gyp;
  const double txx = 2.0 * x * y / (r2 * r2), txy = (y * y - x * x) / (r2 * r2);
  *H = tx * Hx + ty * Hy + txx * (gx * gx.transpose() - gy * gy.transpose()) +
       txy * (gx * gy.transpose() + gy * gx.transpose());
  return theta;
}

// θ = wᵀd, w = A_p t̄, d = A_c ā_c + p_c − A_p ā_p − p_p; its Hessian pairs A_p with d's
// entries: ∂²θ/∂A_p,ij ∂(A_c,kl | p_c,k | p_p,k) = δ_ik t̄_j (ā_c,l | 1 | −1) and
// ∂²θ/∂A_p,ij ∂A_p,kl = −δ_ik (t̄_j ā_p,l + t̄_l ā_p,j).
double prismatic(const JointFrame& f, const Vec12& qp, const Vec12& qc, Vec12* gc_out,
                 Vec12* gp_out, Mat24* H) {
  const bool world = f.spec.parent < 0;
  const Vec3 w = affine_A(qp) * f.axis_p;
  const Vec3 d = affine_point(qc, f.anchor_c) - affine_point(qp, f.anchor_p);
  Vec12 gc, gp;
  for (int i = 0; i < 3; ++i) {
    gc[i] = w[i];
    gc.segment<3>(3 + 3 * i) = w[i] * f.anchor_c;
    gp[i] = -w[i];
    gp.segment<3>(3 + 3 * i) = -w[i] * f.anchor_p + d[i] * f.axis_p;
  }
  if (gc_out) *gc_out = gc;
  if (gp_out) *gp_out = world ? Vec12::Zero() : gp;
  if (H) {
    H->setZero();
    if (!world) {
      const Vec3& t = f.axis_p;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const int pij = 12 + a_index(i, j);
          auto put = [&](int other, double value) {
            (*H)(pij, other) += value;
            (*H)(other, pij) += value;
          };
          put(i, t[j]);        // p_c,i
          put(12 + i, -t[j]);  // p_p,i
          for (int l = 0; l < 3; ++l) {
            put(a_index(i, l), t[j] * f.anchor_c[l]);
            (*H)(pij, 12 + a_index(i, l)) -= t[j] * f.anchor_p[l] + t[l] * f.anchor_p[j];
          }
        }
    }
  }
  return w.dot(d);
}

}  // namespace

double joint_limit_coordinate(const JointFrame& f, const VecX& q, Vec12* grad_child,
                              Vec12* grad_parent, Mat24* hessian) {
  const Vec12 qp = body_q(q, f.spec.parent), qc = body_q(q, f.spec.child);
  if (f.spec.kind == JointKind::kPrismatic)
    return prismatic(f, qp, qc, grad_child, grad_parent, hessian);
  return revolute(f, qp, qc, grad_child, grad_parent, hessian);
}

}  // namespace abd
