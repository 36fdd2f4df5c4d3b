#include "contact/damping/normal_damping.h"

#include <algorithm>
#include <cmath>

#include "contact/barrier/barrier.h"
#include "contact/distance/edge_edge_mollifier.h"

namespace abd::contact {
namespace {

// ∂²(κ b)/∂d² from the derivatives w.r.t. s = d²: 2 κ b'(s) + 4 s κ b''(s).
double normal_stiffness(double d2, double d_hat, double xi, double kappa) {
  const double k = 2.0 * kappa * barrier_first_derivative(d2, d_hat, xi) +
                   4.0 * d2 * kappa * barrier_second_derivative(d2, d_hat, xi);
  return std::isfinite(k) ? std::max(k, 0.0) : 0.0;
}

// The edge–edge mollifier's value (1 for other stencils), as the barrier applies it.
double mollifier(const ContactStencil& s, const std::vector<Vec3>& x) {
  if (s.kind != StencilKind::EdgeEdge) return 1.0;
  const auto& v = s.vertices;
  return edge_edge_mollifier_derivatives(x[v[0]], x[v[1]], x[v[2]], x[v[3]], s.eps_x, 0).value;
}

Vec3 stencil_normal(const ContactStencil& s, const StencilGeometry& g) {
  if (s.kind == StencilKind::PointGround) return Vec3::UnitZ();
  return g.basis.col(0).cross(g.basis.col(1)).normalized();
}

}  // namespace

std::vector<DampingStencil> lag_damping(const ActiveSet& set, const std::vector<Vec3>& x_ref,
                                        const BarrierParams& p,
                                        const std::vector<double>& inverse_mass) {
  auto inv = [&](int body) { return body < 0 ? 0.0 : inverse_mass[size_t(body)]; };
  // How many damped pairs share each body's mass.
  std::vector<int> shares(inverse_mass.size(), 0);
  for (const ContactStencil& s : set.stencils) {
    if (!(s.damping > 0.0)) continue;
    for (int b : s.bodies)
      if (b >= 0) ++shares[size_t(b)];
  }
  std::vector<DampingStencil> out;
  for (const ContactStencil& s : set.stencils) {
    if (!(s.damping > 0.0)) continue;
    double inv_m = 0.0;  // 1 / reduced mass of the two shares
    for (int b : s.bodies)
      if (b >= 0) inv_m += inv(b) * shares[size_t(b)];
    if (!(inv_m > 0.0)) continue;
    const StencilGeometry g = stencil_geometry(s, set.x, p.ground_height, 0, true);
    if (g.infeasible) continue;
    const double m = mollifier(s, set.x);
    const double k = m * normal_stiffness(g.d2, p.d_hat, s.xi, p.kappa);
    if (!(k > 0.0)) continue;
    DampingStencil d;
    static_cast<LaggedStencil&>(d) = lagged_stencil(s, g.w, x_ref);
    d.normal = stencil_normal(s, g);
    d.coefficient = 2.0 * s.damping * std::sqrt(k / inv_m);
    out.push_back(d);
  }
  return out;
}

bool same_damping(const std::vector<DampingStencil>& a, const std::vector<DampingStencil>& b,
                  double rtol) {
  return same_lagged(
      a, b, rtol, [](const DampingStencil& d) { return d.coefficient; },
      [](const DampingStencil& d, const DampingStencil& e) {
        return (d.normal - e.normal).cwiseAbs().maxCoeff();
      });
}

StencilEnergy damping_energy(const DampingStencil& s, const std::vector<Vec3>& x, double c,
                             int order) {
  // g = ∂u/∂x: the normal, weighted per vertex; u the normal relative displacement.
  const StencilVec dx = lagged_displacement(s, x);
  StencilVec g(3 * s.nv);
  for (int i = 0; i < s.nv; ++i) g.segment<3>(3 * i) = s.w[i] * s.normal;
  const double u = g.dot(dx);
  const double a = s.coefficient / c;
  StencilEnergy e;
  e.value = 0.5 * a * u * u;
  if (order >= 1) e.grad = (a * u) * g;
  if (order >= 2) e.hess = a * g * g.transpose();
  return e;
}

}  // namespace abd::contact
