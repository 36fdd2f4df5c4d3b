// The World's islands: union-find over bodies (roots are the smallest index), with the
// line-search state an island carries.
#include <algorithm>

#include "solver/world.h"

namespace abd {

// Joins the islands of a and b (root: the smaller index). The merged island takes the smaller
// step bound and must iterate again (it is neither converged nor frozen).
bool World::merge_islands(int a, int b) {
  a = island(a);
  b = island(b);
  if (a == b) return false;
  if (b < a) std::swap(a, b);
  parent_[b] = a;
  alpha_[a] = std::min(alpha_[a], alpha_[b]);
  converged_[a] = converged_[b] = 0;
  frozen_[a] = frozen_[b] = 0;
  pending_[a] = pending_[a] || pending_[b];
  damping_[a] = std::max(damping_[a], damping_[b]);
  return true;
}

}  // namespace abd
