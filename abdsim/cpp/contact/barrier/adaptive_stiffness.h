// IPC's adaptive barrier stiffness (Li et al. 2020), rescaled to abdsim's incremental
// potential. abdsim writes Π = ½|q − q̃|²_M + h² (Ψ + κ B₁) (every term is scaled by h² in
// the solver), while IPC writes E = ½|x − x̃|²_M + h² Ψ + κ_IPC B₁; hence κ = κ_IPC / h².
// B₁ is the barrier sum with unit stiffness.
//
//  * κ_min: the barrier's curvature (in distance units) at a tiny gap d₀ = 1e-8 · bbox diagonal
//    must be `scale` (IPC: 1e11) times the average mass: κ_min = scale m̄ / (h² · 4 x₀ b''(x₀)),
//    x₀ = (ξ + d₀)². κ_max = 100 κ_min.
//  * initial κ balances the barrier gradient against the rest of Π's gradient:
//    κ = −(∇B₁ · ∇E)/(h² |∇B₁|²), clamped to [κ_min, κ_max] (κ_min when nothing is in contact).
//  * update: when the smallest gap stays below ε_d = eps_scale · diagonal and keeps shrinking,
//    double κ (up to κ_max).
#pragma once
#include "common/types.h"

namespace abd::contact {

struct BarrierStiffness {
  double kappa = 0.0;
  double kappa_min = 0.0;
  double kappa_max = 0.0;
};

constexpr double kBarrierStiffnessScale = 1e11;

double min_barrier_stiffness(double bbox_diagonal, double d_hat, double average_mass, double dt,
                             double xi = 0.0, double scale = kBarrierStiffnessScale);

// grad_rest: gradient of Π without the barrier; grad_barrier: ∇B₁ (unit κ, not scaled by h²).
BarrierStiffness initial_barrier_stiffness(double bbox_diagonal, double d_hat,
                                           double average_mass, double dt,
                                           const VecX& grad_rest, const VecX& grad_barrier,
                                           double xi = 0.0,
                                           double scale = kBarrierStiffnessScale);

// The balance alone, unclamped: −(∇B₁ · ∇E)/(h² |∇B₁|²), or 0 when ∇B₁ = 0.
double balanced_barrier_stiffness(double dt, const VecX& grad_rest, const VecX& grad_barrier);

double update_barrier_stiffness(double prev_min_gap, double min_gap, double kappa_max,
                                double kappa, double bbox_diagonal, double eps_scale = 1e-9);

}  // namespace abd::contact
