// Lagged IPC friction potential of one stencil (Li et al. 2020, §5). Lagged at the start of
// the step: the closest-point weights w, the tangent basis T and the normal force λ. With the
// stencil's displacement since then, Δx = x − x_t (3·nv values),
//     u = Tᵀ Σ_i w_i Δx_i = Γ Δx,     D = μ λ f0(|u|; ε),  ε = ε_v h,
//     ∇D = μλ f1(|u|)/|u| Γᵀ u,
//     ∇²D = μλ Γᵀ [ f1/|u| I + (f2 |u| − f1)/|u|³ u uᵀ ] Γ.
// The 2×2 middle matrix is PSD analytically (eigenvalues f1/|u| ≥ 0 across u and f2 ≥ 0 along
// it); we clamp its eigenvalue along u at zero so rounding cannot break that, which keeps the
// whole Hessian PSD without an eigen-decomposition.
#pragma once
#include "contact/stencil_types.h"

namespace abd::contact {

struct FrictionDerivatives {
  double value = 0.0;
  StencilVec grad;
  StencilMat hess;
};

FrictionDerivatives friction_potential(const StencilVec& dx, const StencilWeights& w,
                                       const Mat3x2& T, double mu_lambda, double eps, int order);

}  // namespace abd::contact
