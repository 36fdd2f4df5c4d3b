// Lagged IPC friction potential of one stencil (Li et al. 2020, §5). Lagged at the start of
// the step: the closest-point weights w, the tangent basis T and the normal force λ. With the
// stencil's displacement since then, Δx = x − x_t (3·nv values),
//     u = Tᵀ Σ_i w_i Δx_i = Γ Δx,     D = μ λ f0(|u|; ε),  ε = ε_v h,
//     ∇D = μλ f1(|u|)/|u| Γᵀ u,
//     ∇²D = μλ Γᵀ [ f1/|u| I + (f2 |u| − f1)/|u|³ u uᵀ ] Γ.
// The 2×2 middle matrix is PSD analytically (eigenvalues f1/|u| ≥ 0 across u and f2 ≥ 0 along
// it); we clamp its eigenvalue along u at zero so rounding cannot break that, which keeps the
// whole Hessian PSD without an eigen-decomposition.
// majorize: the middle matrix f1/|u| I instead (the eigenvalue along u raised to the one
// across). Its quadratic model bounds D from above for every step: f0(√s) is concave in
// s = |u|² (both pieces are, and f0 is C¹), so f0(|u|) ≤ f0(|u₀|) + f1(|u₀|)/(2|u₀|) (|u|² −
// |u₀|²) (IRLS / Weiszfeld). The exact model is linear along a sliding u (f2 = 0), and a
// Newton step that stops the slide overshoots through the kink, where D rises as 2μλ times
// the overshoot above that line; the majorising model cannot.
#pragma once
#include "contact/stencil_types.h"

namespace abd::contact {

struct FrictionDerivatives {
  double value = 0.0;
  StencilVec grad;
  StencilMat hess;
};

FrictionDerivatives friction_potential(const StencilVec& dx, const StencilWeights& w,
                                       const Mat3x2& T, double mu_lambda, double eps, int order,
                                       bool majorize = false);

}  // namespace abd::contact
