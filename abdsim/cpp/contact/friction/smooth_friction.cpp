#include "contact/friction/smooth_friction.h"

#include <cmath>

namespace abd::contact {

double smooth_friction_f0(double y, double eps) {
  const double a = std::abs(y);
  if (a >= eps) return a;
  return -a * a * a / (3.0 * eps * eps) + a * a / eps + eps / 3.0;
}

double smooth_friction_f1(double y, double eps) {
  const double a = std::abs(y);
  if (a >= eps) return 1.0;
  return -a * a / (eps * eps) + 2.0 * a / eps;
}

double smooth_friction_f2(double y, double eps) {
  const double a = std::abs(y);
  if (a >= eps) return 0.0;
  return -2.0 * a / (eps * eps) + 2.0 / eps;
}

double smooth_friction_f1_over_x(double y, double eps) {
  const double a = std::abs(y);
  if (a >= eps) return 1.0 / a;
  return -a / (eps * eps) + 2.0 / eps;
}

double smooth_friction_f2_x_minus_f1_over_x3(double y, double eps) {
  const double a = std::abs(y);
  if (a >= eps) return -1.0 / (a * a * a);
  return -1.0 / (a * eps * eps);
}

}  // namespace abd::contact
