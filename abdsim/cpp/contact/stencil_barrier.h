// The barrier potential of one stencil in vertex space:  κ m(c) b(d²; d̂, ξ), with m the
// edge–edge mollifier (1 for other stencils). Gradient and Hessian are w.r.t. the stencil's
// 3·nv coordinates; the Hessian is projected to PSD here, per stencil, so that its body-space
// image Jᵀ H J is PSD too (body_mapping.h).
#pragma once
#include <vector>

#include "contact/contact_stencil.h"

namespace abd::contact {

struct BarrierParams {
  double d_hat = 1e-3;
  double kappa = 1.0;
  double ground_height = 0.0;
  bool project_psd = true;
};

struct StencilEnergy {
  double value = 0.0;  // +inf when the stencil is infeasible (derivatives are then zero)
  StencilVec grad;
  StencilMat hess;
};

// order: 0 value, 1 + gradient, 2 + Hessian.
StencilEnergy stencil_barrier(const ContactStencil& s, const std::vector<Vec3>& x,
                              const BarrierParams& p, int order);

// The value of stencil_barrier(s, x, p, 0) from the stencil's distance at x, already known
// (ActiveSet::distances): the same number without computing the distance again.
double stencil_barrier_value(const ContactStencil& s, const StencilDistance& d,
                             const std::vector<Vec3>& x, const BarrierParams& p);

// IPC's normal force magnitude λ = −∂(κ m b)/∂d at the current positions (0 when inactive),
// the quantity friction lags at the start of a step.
double stencil_normal_force(const ContactStencil& s, const StencilGeometry& g,
                            const std::vector<Vec3>& x, const BarrierParams& p);

}  // namespace abd::contact
