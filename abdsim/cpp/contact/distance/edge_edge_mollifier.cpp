#include "contact/distance/edge_edge_mollifier.h"

namespace abd::contact {
namespace {

// With u = ea1 − ea0, v = eb1 − eb0:  c = |u|²|v|² − (u·v)²,
//   ∂c/∂u = 2|v|² u − 2(u·v) v,   ∂c/∂v = 2|u|² v − 2(u·v) u,
//   ∂²c/∂u² = 2|v|² I − 2 v vᵀ,   ∂²c/∂v² = 2|u|² I − 2 u uᵀ,
//   ∂²c/∂u∂v = 4 u vᵀ − 2 v uᵀ − 2 (u·v) I.
// The chain rule to the vertices uses ∂u/∂[ea0, ea1] = [−I, I] (likewise v).
Vec12 chain_gradient(const Vec3& gu, const Vec3& gv) {
  Vec12 g;
  g << -gu, gu, -gv, gv;
  return g;
}

}  // namespace

double edge_edge_mollifier_threshold(const Vec3& ea0_rest, const Vec3& ea1_rest,
                                     const Vec3& eb0_rest, const Vec3& eb1_rest) {
  return kMollifierThresholdScale * (ea1_rest - ea0_rest).squaredNorm() *
         (eb1_rest - eb0_rest).squaredNorm();
}

double edge_edge_cross_squarednorm(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                   const Vec3& eb1) {
  return (ea1 - ea0).cross(eb1 - eb0).squaredNorm();
}

Vec12 edge_edge_cross_squarednorm_gradient(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                           const Vec3& eb1) {
  const Vec3 u = ea1 - ea0, v = eb1 - eb0;
  const double uv = u.dot(v);
  return chain_gradient(2.0 * v.squaredNorm() * u - 2.0 * uv * v,
                        2.0 * u.squaredNorm() * v - 2.0 * uv * u);
}

Mat12 edge_edge_cross_squarednorm_hessian(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                          const Vec3& eb1) {
  const Vec3 u = ea1 - ea0, v = eb1 - eb0;
  const Mat3 I = Mat3::Identity();
  const Mat3 Huu = 2.0 * v.squaredNorm() * I - 2.0 * v * v.transpose();
  const Mat3 Hvv = 2.0 * u.squaredNorm() * I - 2.0 * u * u.transpose();
  const Mat3 Huv = 4.0 * u * v.transpose() - 2.0 * v * u.transpose() - 2.0 * u.dot(v) * I;
  // Blocks in (u, v) space, then D = ∂(u,v)/∂x with signs s = [−1, +1] per edge endpoint.
  Mat12 H;
  const double s[2] = {-1.0, 1.0};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const double sij = s[i] * s[j];
      H.block<3, 3>(3 * i, 3 * j) = sij * Huu;
      H.block<3, 3>(6 + 3 * i, 6 + 3 * j) = sij * Hvv;
      H.block<3, 3>(3 * i, 6 + 3 * j) = sij * Huv;
      H.block<3, 3>(6 + 3 * j, 3 * i) = sij * Huv.transpose();
    }
  return H;
}

double edge_edge_mollifier(double c, double eps_x) {
  if (c >= eps_x) return 1.0;
  const double y = c / eps_x;
  return (2.0 - y) * y;
}

double edge_edge_mollifier_derivative(double c, double eps_x) {
  return c >= eps_x ? 0.0 : 2.0 / eps_x - 2.0 * c / (eps_x * eps_x);
}

double edge_edge_mollifier_second_derivative(double c, double eps_x) {
  return c >= eps_x ? 0.0 : -2.0 / (eps_x * eps_x);
}

Mollifier edge_edge_mollifier_derivatives(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                          const Vec3& eb1, double eps_x, int order) {
  Mollifier m;
  const double c = edge_edge_cross_squarednorm(ea0, ea1, eb0, eb1);
  if (c >= eps_x) return m;
  m.active = true;
  m.value = edge_edge_mollifier(c, eps_x);
  if (order < 1) return m;
  const Vec12 gc = edge_edge_cross_squarednorm_gradient(ea0, ea1, eb0, eb1);
  const double m1 = edge_edge_mollifier_derivative(c, eps_x);
  m.grad = m1 * gc;
  if (order < 2) return m;
  m.hess = edge_edge_mollifier_second_derivative(c, eps_x) * gc * gc.transpose() +
           m1 * edge_edge_cross_squarednorm_hessian(ea0, ea1, eb0, eb1);
  return m;
}

}  // namespace abd::contact
