// Lagged friction (IPC §5): at the start of a step, each active stencil with μ > 0 freezes its
// closest-point weights w, tangent basis T and normal force λ, and remembers its vertices'
// positions x_t. During the step, friction is the smooth potential of the sliding of the
// closest points since then (friction/friction_potential.h), a fixed set of terms.
#pragma once
#include <array>
#include <vector>

#include "contact/active_set.h"
#include "contact/stencil_barrier.h"

namespace abd::contact {

struct FrictionStencil {
  int nv = 0;
  std::array<int, 4> vertices{};
  StencilWeights w;
  Mat3x2 basis;
  double mu_lambda = 0.0;
  StencilVec x_t;  // stencil coordinates at the start of the step
};

std::vector<FrictionStencil> lag_friction(const ActiveSet& at_step_start, const BarrierParams& p);

// μλ f0(|Tᵀ Σ w_i (x_i − x_i^t)|; eps) with gradient and (PSD) Hessian in stencil coordinates.
StencilEnergy friction_energy(const FrictionStencil& f, const std::vector<Vec3>& x, double eps,
                              int order);

}  // namespace abd::contact
