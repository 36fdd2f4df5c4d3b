// IPC's C¹ friction mollifier (Li et al. 2020, §5): static friction is replaced by a stiff
// regime below the smoothing displacement ε = ε_v h, so that the friction force
// −μλ f1(|u|) u/|u| is continuous and vanishes at u = 0.
//   f0(y) = −y³/(3ε²) + y²/ε + ε/3  (|y| < ε),   y  (|y| ≥ ε)
//   f1 = f0',  f2 = f1'.
// The "over" forms avoid 0/0 at y = 0 and are what the gradient and Hessian actually use.
#pragma once

namespace abd::contact {

double smooth_friction_f0(double y, double eps);
double smooth_friction_f1(double y, double eps);
double smooth_friction_f2(double y, double eps);
double smooth_friction_f1_over_x(double y, double eps);            // f1(y)/y
double smooth_friction_f2_x_minus_f1_over_x3(double y, double eps);  // (f2 y − f1)/y³

}  // namespace abd::contact
