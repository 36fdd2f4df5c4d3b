#include "joints/joint_potentials.h"

#include <algorithm>
#include <cmath>

namespace abd {

void add_quadratic(Scalar1D& out, double k, double x, double x0) {
  const double r = x - x0;
  out.e += 0.5 * k * r * r;
  out.d1 += k * r;
  out.d2 += k;
}

void add_linear_force(Scalar1D& out, double tau, double x) {
  out.e -= tau * x;
  out.d1 -= tau;
}

void add_dry_friction(Scalar1D& out, double F, double theta, double theta_hat, double c,
                      double eps) {
  // φ(y) = y²/ε − y³/(3ε²) below ε, y − ε/3 above: φ' = f₁(y) = 2y/ε − y²/ε² (IPC), C¹.
  const double v = (theta - theta_hat) / c;
  const double y = std::abs(v), sign = v < 0.0 ? -1.0 : 1.0;
  if (y < eps) {
    out.e += F * c * (y * y / eps - y * y * y / (3.0 * eps * eps));
    out.d1 += F * sign * (2.0 * y / eps - y * y / (eps * eps));
    out.d2 += F * (2.0 / eps - 2.0 * y / (eps * eps)) / c;
  } else {
    out.e += F * c * (y - eps / 3.0);
    out.d1 += F * sign;
  }
}

bool add_limit_barrier(Scalar1D& out, double theta, double bound, int sign, double d_hat,
                       double kappa) {
  const double d = sign * (theta - bound);
  if (d <= 0.0) return false;
  if (d >= d_hat) return true;
  const double l = std::log(d / d_hat), r = d - d_hat;
  out.e += -kappa * r * r * l;
  const double db = -kappa * (2.0 * r * l + r * r / d);
  out.d1 += sign * db;
  out.d2 += -kappa * (2.0 * l + 4.0 * r / d - r * r / (d * d));
  return true;
}

void add_clamped_actuator(Scalar1D& out, double theta, double gear, double F0, double F1,
                          double lo, double hi) {
  const double y = F0 + F1 * theta;
  if (F1 == 0.0) {  // no position or velocity feedback: a constant force
    add_linear_force(out, gear * std::clamp(y, lo, hi), theta);
    return;
  }
  // G(y): an antiderivative of clamp(y, lo, hi) (C¹); E = −(gear / F1) G(y) gives
  // E' = −gear clamp(y) and E'' = −gear F1 >= 0 inside the range, 0 where it saturates.
  const double G = y < lo ? lo * y - 0.5 * lo * lo : y > hi ? hi * y - 0.5 * hi * hi : 0.5 * y * y;
  out.e += -(gear / F1) * G;
  out.d1 += -gear * std::clamp(y, lo, hi);
  if (y > lo && y < hi) out.d2 += -gear * F1;
}

}  // namespace abd
