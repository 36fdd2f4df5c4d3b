#include "contact/barrier/adaptive_stiffness.h"

#include <algorithm>
#include <stdexcept>

#include "contact/barrier/barrier.h"

namespace abd::contact {

double min_barrier_stiffness(double bbox_diagonal, double d_hat, double average_mass, double dt,
                             double xi, double scale) {
  if (!(d_hat > 0.0) || !(dt > 0.0) || !(bbox_diagonal > 0.0))
    throw std::invalid_argument("min_barrier_stiffness: d_hat, dt and bbox_diagonal must be > 0");
  double gap = 1e-8 * bbox_diagonal;
  // A d̂ tinier than that gap would put x₀ outside the barrier's support.
  if (gap >= d_hat) gap = 0.5 * d_hat;
  const double x0 = (xi + gap) * (xi + gap);
  const double curvature = 4.0 * x0 * barrier_second_derivative(x0, d_hat, xi);
  return scale * average_mass / (curvature * dt * dt);
}

BarrierStiffness initial_barrier_stiffness(double bbox_diagonal, double d_hat,
                                           double average_mass, double dt,
                                           const VecX& grad_rest, const VecX& grad_barrier,
                                           double xi, double scale) {
  BarrierStiffness s;
  s.kappa_min = min_barrier_stiffness(bbox_diagonal, d_hat, average_mass, dt, xi, scale);
  s.kappa_max = 100.0 * s.kappa_min;
  s.kappa = s.kappa_min;
  const double gb2 = grad_barrier.squaredNorm();
  if (gb2 > 0.0 && grad_rest.size() == grad_barrier.size())
    s.kappa = std::clamp(balanced_barrier_stiffness(dt, grad_rest, grad_barrier), s.kappa_min,
                         s.kappa_max);
  return s;
}

double balanced_barrier_stiffness(double dt, const VecX& grad_rest, const VecX& grad_barrier) {
  const double gb2 = grad_barrier.squaredNorm();
  if (!(gb2 > 0.0) || grad_rest.size() != grad_barrier.size()) return 0.0;
  return -grad_barrier.dot(grad_rest) / (dt * dt * gb2);
}

double update_barrier_stiffness(double prev_min_gap, double min_gap, double kappa_max,
                                double kappa, double bbox_diagonal, double eps_scale) {
  const double eps_d = eps_scale * bbox_diagonal;
  if (prev_min_gap < eps_d && min_gap < eps_d && min_gap < prev_min_gap)
    return std::min(kappa_max, 2.0 * kappa);
  return kappa;
}

}  // namespace abd::contact
