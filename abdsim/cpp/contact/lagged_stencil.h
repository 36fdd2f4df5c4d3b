// What every lagged stencil (friction, damping) freezes at the step start: its vertices, the
// closest-point weights w (r = Σ w_i x_i joins the closest points) and the stencil's
// coordinates x_t at the integrator's reference point; and whether two lists of them are the
// same for the step (lagging again at a converged state changes nothing that matters).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "contact/contact_stencil.h"

namespace abd::contact {

struct LaggedStencil {
  int nv = 0;
  std::array<int, 4> vertices{};
  StencilWeights w;
  StencilVec x_t;  // stencil coordinates at the reference point (the step start for BDF1)
};

// The stencil of `s` with weights w, its reference coordinates taken from x_ref.
inline LaggedStencil lagged_stencil(const ContactStencil& s, const StencilWeights& w,
                                    const std::vector<Vec3>& x_ref) {
  LaggedStencil l;
  l.nv = s.nv;
  l.vertices = s.vertices;
  l.w = w;
  l.x_t = gather_positions(s, x_ref);
  return l;
}

// Δx = x − x_t over the stencil's 3·nv coordinates.
inline StencilVec lagged_displacement(const LaggedStencil& l, const std::vector<Vec3>& x) {
  StencilVec dx(3 * l.nv);
  for (int i = 0; i < l.nv; ++i) dx.segment<3>(3 * i) = x[l.vertices[i]] - l.x_t.segment<3>(3 * i);
  return dx;
}

// Same stencils, strengths within rtol of the largest, directions within rtol.
template <class Stencil, class Strength, class DirectionGap>
bool same_lagged(const std::vector<Stencil>& a, const std::vector<Stencil>& b, double rtol,
                 const Strength& strength, const DirectionGap& direction_gap) {
  if (a.size() != b.size()) return false;
  double largest = 0.0;
  for (const Stencil& s : a) largest = std::max(largest, strength(s));
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].nv != b[i].nv || a[i].vertices != b[i].vertices) return false;
    if (std::abs(strength(a[i]) - strength(b[i])) > rtol * largest) return false;
    if (direction_gap(a[i], b[i]) > rtol) return false;
  }
  return true;
}

}  // namespace abd::contact
