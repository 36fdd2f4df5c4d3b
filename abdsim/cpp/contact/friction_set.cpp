#include "contact/friction_set.h"

#include <algorithm>
#include <cmath>

#include "contact/friction/friction_potential.h"

namespace abd::contact {

std::vector<FrictionStencil> lag_friction(const ActiveSet& set, const std::vector<Vec3>& x_ref,
                                          const BarrierParams& p) {
  std::vector<FrictionStencil> out;
  for (const ContactStencil& s : set.stencils) {
    if (!(s.mu > 0.0)) continue;
    const StencilGeometry g = stencil_geometry(s, set.x, p.ground_height, 0, true);
    const double lambda = stencil_normal_force(s, g, set.x, p);
    if (!(lambda > 0.0) || !std::isfinite(lambda)) continue;
    FrictionStencil f;
    static_cast<LaggedStencil&>(f) = lagged_stencil(s, g.w, x_ref);
    f.basis = g.basis;
    f.mu_lambda = s.mu * lambda;
    out.push_back(f);
  }
  return out;
}

bool same_friction(const std::vector<FrictionStencil>& a, const std::vector<FrictionStencil>& b,
                   double rtol) {
  return same_lagged(
      a, b, rtol, [](const FrictionStencil& f) { return f.mu_lambda; },
      [](const FrictionStencil& f, const FrictionStencil& g) {
        return (f.basis - g.basis).cwiseAbs().maxCoeff();
      });
}

StencilEnergy friction_energy(const FrictionStencil& f, const std::vector<Vec3>& x, double eps,
                              int order, bool majorize) {
  const StencilVec dx = lagged_displacement(f, x);
  const FrictionDerivatives d =
      friction_potential(dx, f.w, f.basis, f.mu_lambda, eps, order, majorize);
  return {d.value, d.grad, d.hess};
}

}  // namespace abd::contact
