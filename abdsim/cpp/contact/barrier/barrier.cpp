#include "contact/barrier/barrier.h"

#include <cmath>
#include <limits>

namespace abd::contact {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}

double barrier(double d2, double d_hat, double xi) {
  const double X = (d_hat + xi) * (d_hat + xi), Y = xi * xi;
  if (d2 >= X) return 0.0;
  if (d2 <= Y) return kInf;
  const double dx = d2 - X;
  return -dx * dx * std::log((d2 - Y) / (X - Y));
}

double barrier_first_derivative(double d2, double d_hat, double xi) {
  const double X = (d_hat + xi) * (d_hat + xi), Y = xi * xi;
  if (d2 >= X) return 0.0;
  if (d2 <= Y) return -kInf;
  const double dx = d2 - X, s = d2 - Y;
  return -dx * (2.0 * std::log(s / (X - Y)) + dx / s);
}

double barrier_second_derivative(double d2, double d_hat, double xi) {
  const double X = (d_hat + xi) * (d_hat + xi), Y = xi * xi;
  if (d2 >= X) return 0.0;
  if (d2 <= Y) return kInf;
  const double dx = d2 - X, s = d2 - Y;
  const double ratio = dx / s;
  return -(2.0 * std::log(s / (X - Y)) + 4.0 * ratio - ratio * ratio);
}

double barrier_force_magnitude(double d2, double d_hat, double xi, double kappa) {
  return -2.0 * std::sqrt(d2) * kappa * barrier_first_derivative(d2, d_hat, xi);
}

}  // namespace abd::contact
