// Scalar potentials in one joint coordinate θ (rad or m) whose minimisation inside the
// incremental potential reproduces MuJoCo's joint physics and actuators (ABD_NOTES §8). With
// c the BDF factor (h, or 2h/3), θ̂ the BDF history point and θ̃ = θ̂ + c θ̇̂ the prediction,
// the implicit joint velocity is (θ − θ̂)/c and, in potential units (the solver scales by c²):
//   spring    ½ k (θ − ref)²                       → −k (θ − ref)
//   damping   b (θ − θ̂)² / (2c)                    → −b θ̇
//   armature  a (θ − θ̃)² / (2c²)                   → the inertia a on θ
//   force     −τ θ                                  → τ (qfrc_applied, motors)
//   friction  F c φ(|θ − θ̂|/c), φ' = IPC's f₁ (ε)  → −F sign(θ̇), smoothed below ε
//   limit     IPC barrier −κ (d − d̂)² ln(d/d̂), d = θ − lower or upper − θ, 0 < d < d̂
//   actuator  force y = F0 + F1 θ (F1 <= 0) clamped to [lo, hi], torque gear·clamp(y):
//             the convex Huber-like energy with E' = −gear·clamp(y)
// Each adds its value, first and second derivative in θ (second: >= 0, convex).
#pragma once

namespace abd {

struct Scalar1D {
  double e = 0.0;
  double d1 = 0.0;
  double d2 = 0.0;
};

void add_quadratic(Scalar1D& out, double k, double x, double x0);
void add_linear_force(Scalar1D& out, double tau, double x);
// Smoothed dry friction of magnitude F at speed v = (θ − θ̂)/c, smoothing speed eps.
void add_dry_friction(Scalar1D& out, double F, double theta, double theta_hat, double c,
                      double eps);
// Barrier of a lower (sign = +1: d = θ − bound) or upper (sign = −1: d = bound − θ) limit.
// Returns false when d <= 0 (infeasible).
bool add_limit_barrier(Scalar1D& out, double theta, double bound, int sign, double d_hat,
                       double kappa);
// gear · clamp(F0 + F1 θ, lo, hi) as a generalized force (F1 <= 0).
void add_clamped_actuator(Scalar1D& out, double theta, double gear, double F0, double F1,
                          double lo, double hi);

}  // namespace abd
