// Contact dissipation: a lagged viscous damper on the normal gap of each active pair.
//
// At the start of a step each active stencil (inside d̂) with damping ratio ζ > 0 freezes its
// closest-point weights w, its normal n and a damper coefficient
//     C = 2 ζ √(k m),   k = ∂²(κ m_c b)/∂d² at the lagged gap (the barrier's normal stiffness),
// with m the pair's reduced translational mass (each body's mass shared among its damped
// pairs, so a box on four corners is damped as one spring of stiffness 4k). During the step
// the pair adds the incremental potential
//     D(x) = C / (2c) · (nᵀ Σ w_i (x_i − x_i^ref))²
// (c = h for BDF1, 2h/3 for BDF2, x^ref the integrator's reference point; the solver scales
// by c²), whose force is −C v_n n: a dashpot on the normal relative velocity. It is a convex
// quadratic (Hessian C/c · g gᵀ, PSD), so the step can only lose energy through it, and it
// changes nothing the barrier or CCD guarantee. k, and so C, vanish as the gap reaches d̂
// (b'' = 0 there): the damper fades in with the barrier. Dampers are not lagged again after
// convergence (unlike friction): a damper lagged inside d̂ at the end of the step that
// reached the surface would brake the whole step's fall, outside d̂ too (a body dropped
// onto the ground hovered above d̂ for tens of milliseconds before touching); the impact
// step is the barrier's, the steps after it are damped.
#pragma once
#include <array>
#include <vector>

#include "contact/active_set.h"
#include "contact/lagged_stencil.h"
#include "contact/stencil_barrier.h"

namespace abd::contact {

struct DampingStencil : LaggedStencil {
  Vec3 normal = Vec3::UnitZ();
  double coefficient = 0.0;  // C (N·s/m)
};

// Dampers of the active stencils of `set` with damping > 0. inverse_mass: per body 1/m, 0
// for bodies the dynamics does not move (fixed, scripted); pairs where both are 0 are left out.
std::vector<DampingStencil> lag_damping(const ActiveSet& set, const std::vector<Vec3>& x_ref,
                                        const BarrierParams& p,
                                        const std::vector<double>& inverse_mass);

// The same stencils with coefficients within `rtol` (relative to the largest) and normals
// within `rtol`: lagging again would change nothing that matters.
bool same_damping(const std::vector<DampingStencil>& a, const std::vector<DampingStencil>& b,
                  double rtol = 1e-3);

// D(x) with gradient and Hessian in stencil coordinates; c the step's time scale (> 0).
StencilEnergy damping_energy(const DampingStencil& s, const std::vector<Vec3>& x, double c,
                             int order);

}  // namespace abd::contact
