// Box-only traversals of coal BVHs (body_bvh.h). We walk coal's public BVNode tree
// ourselves rather than calling coal::collide: we want every pair of *leaf boxes* within a
// margin (our own distance code decides what is really close), including for swept boxes,
// for which coal's triangle-level narrow phase has no meaning.
#pragma once
#include <functional>

#include "contact/broad_phase/affine_frame.h"
#include "contact/broad_phase/body_bvh.h"

namespace abd::contact {

// Boxes a and b come within `margin` of each other on every axis (so any two points in them
// may be closer than `margin`; points farther apart than margin never pass).
inline bool boxes_within(const coal::AABB& a, const coal::AABB& b, double margin) {
  for (int k = 0; k < 3; ++k)
    if (a.min_[k] > b.max_[k] + margin || b.min_[k] > a.max_[k] + margin) return false;
  return true;
}

// A box around the image of a rest box under an affine map (plus the map's slack): the box
// around a parallelepiped, centre A c + p, half-sizes |A| h.
coal::AABB affine_box(const coal::AABB& rest, const AffineMap& m);

// The world boxes of one tree's nodes at a query. Either the tree was refit to the world
// positions (affine = nullptr: its own boxes), or it is still at rest and the body moves by
// known affine maps: an inner node's box is then bounded by the image of its rest box (the
// box around a parallelepiped, O(1) per node, no refit of the tree), and a leaf's box is the
// exact box around its primitive's world vertices. Swept (affine1 set, x1 set): the union of
// the boxes at both ends, which holds the whole straight motion (box centres move linearly
// and half-sizes |A(t)| h stay below the interpolation of the ends').
struct TreeBoxes {
  const Bvh* tree = nullptr;
  const AffineMap* affine0 = nullptr;
  const AffineMap* affine1 = nullptr;
  const Vec3* x0 = nullptr;  // the body's world vertices (its first one)
  const Vec3* x1 = nullptr;
  // Every node's box at this query, computed once (small trees, see BroadPhase::fit): a
  // dual-tree descent asks for the same node once per node of the other tree.
  const coal::AABB* cached = nullptr;

  coal::AABB node(int i) const;
};

// emit(i, j) for every leaf i of a and leaf j of b whose boxes are within `margin`. Dual-tree
// descent, always splitting the larger box, so the order of emitted pairs is deterministic.
void for_each_close_leaf_pair(const TreeBoxes& a, const TreeBoxes& b, double margin,
                              const std::function<void(int, int)>& emit);

}  // namespace abd::contact
