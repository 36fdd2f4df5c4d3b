// The PSD projection of a stencil's barrier Hessian, computed in the structure of the
// distance's Hessian instead of by a dense eigen-decomposition (stencil_barrier.cpp's
// fallback, 9x9 on the relative motions, was ~14% of a 100-box heap's Newton iteration).
//
// Without the edge–edge mollifier the Hessian of c(d²) is  H = c″ g gᵀ + c′ ∇²d²  with
// g = 2 w ⊗ r and ∇²d² = 2 (w wᵀ ⊗ I₃) − 2 Cᵀ U⁻¹ C,  C_k = a_k ⊗ r + w ⊗ u_k  (k < nb ≤ 2;
// affine_distance.h). Its range lies in the span of the 3 + nb vectors w ⊗ e_i and C_k, so
// H = Q S Qᵀ with Q an orthonormal basis of that span and S = QᵀHQ at most 5x5, and its
// projection is Q P(S) Qᵀ: the same matrix as the dense projection (up to round-off).
// Q is built without cancellation: w ⊗ e_i / |w| (orthonormal by construction), then
// q̃_l ⊗ r̂, q̃ an orthonormal basis of the a_k with their w-parts removed (C_k's part outside
// the first three is exactly ã_k ⊗ r).
#pragma once
#include "contact/contact_stencil.h"

namespace abd::contact {

// out = P(c2 g gᵀ + c1 ∇²d²) from g's factors (a point–triangle or edge–edge stencil's
// geometry at order 2). False (out untouched) where the basis degenerates (r = 0, w = 0):
// the caller projects the dense matrix then.
bool project_barrier_hessian(const StencilGeometry& g, double c2, double c1, StencilMat& out);

}  // namespace abd::contact
