// Lagged friction (IPC §5): at the start of a step, each active stencil with μ > 0 freezes its
// closest-point weights w, tangent basis T and normal force λ, and remembers its vertices'
// positions x_t. During the step, friction is the smooth potential of the sliding of the
// closest points since then (friction/friction_potential.h), a fixed set of terms.
#pragma once
#include <array>
#include <vector>

#include "contact/active_set.h"
#include "contact/lagged_stencil.h"
#include "contact/stencil_barrier.h"

namespace abd::contact {

struct FrictionStencil : LaggedStencil {
  Mat3x2 basis;
  double mu_lambda = 0.0;
};

// Weights, bases and normal forces from `set` (the step start, or a converged iterate); the
// sliding is measured from the vertex positions x_ref (the integrator's reference point).
std::vector<FrictionStencil> lag_friction(const ActiveSet& set, const std::vector<Vec3>& x_ref,
                                          const BarrierParams& p);

// The same stencils with normal forces within `rtol` of each other (relative to the largest)
// and tangent bases within `rtol`: lagging again would change nothing that matters.
bool same_friction(const std::vector<FrictionStencil>& a, const std::vector<FrictionStencil>& b,
                   double rtol = 1e-3);

// μλ f0(|Tᵀ Σ w_i (x_i − x_i^t)|; eps) with gradient and (PSD) Hessian in stencil coordinates;
// majorize: the Hessian of the model that bounds it from above (friction_potential.h).
StencilEnergy friction_energy(const FrictionStencil& f, const std::vector<Vec3>& x, double eps,
                              int order, bool majorize = false);

}  // namespace abd::contact
