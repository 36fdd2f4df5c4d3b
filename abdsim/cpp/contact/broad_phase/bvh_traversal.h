// Box-only traversals of coal BVHs (body_bvh.h). We walk coal's public BVNode tree
// ourselves rather than calling coal::collide: we want every pair of *leaf boxes* within a
// margin (our own distance code decides what is really close), including for swept boxes,
// for which coal's triangle-level narrow phase has no meaning.
#pragma once
#include <functional>

#include "contact/broad_phase/body_bvh.h"

namespace abd::contact {

// Boxes a and b come within `margin` of each other on every axis (so any two points in them
// may be closer than `margin`; points farther apart than margin never pass).
inline bool boxes_within(const coal::AABB& a, const coal::AABB& b, double margin) {
  for (int k = 0; k < 3; ++k)
    if (a.min_[k] > b.max_[k] + margin || b.min_[k] > a.max_[k] + margin) return false;
  return true;
}

// emit(i, j) for every leaf i of a and leaf j of b whose boxes are within `margin`. Dual-tree
// descent, always splitting the larger box, so the order of emitted pairs is deterministic.
void for_each_close_leaf_pair(const Bvh& a, const Bvh& b, double margin,
                              const std::function<void(int, int)>& emit);

}  // namespace abd::contact
