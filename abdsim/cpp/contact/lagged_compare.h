// Whether two lists of lagged stencils (friction, damping) are the same for the step: the
// same stencils, strengths within rtol of the largest, directions within rtol. Lagging
// again at a converged state changes nothing that matters when this holds.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

namespace abd::contact {

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
