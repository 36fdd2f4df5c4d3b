// Body-level culling with coal's broad-phase manager (a dynamic AABB tree over one
// CollisionObject per body). Only pairs of bodies whose boxes overlap go on to the
// primitive-level traversal (broad_phase.h), so a scene of many bodies costs about
// O(n log n + overlapping pairs) rather than O(n²).
//
// coal's managers test plain AABBs and ignore CollisionRequest::security_margin, so the
// caller hands in boxes that are already grown by the query's margin (d̂ and thickness, or the
// step's motion for CCD). We write those boxes into the objects directly; the objects'
// geometry is a placeholder that the manager never looks at.
#pragma once
#include <memory>
#include <utility>
#include <vector>

#include <coal/broadphase/broadphase_dynamic_AABB_tree.h>
#include <coal/collision_object.h>

namespace abd::contact {

class BodyPairFinder {
 public:
  explicit BodyPairFinder(int n_bodies);

  // Pairs (a, b), a < b, of bodies whose boxes overlap; sorted.
  std::vector<std::pair<int, int>> overlapping(const std::vector<coal::AABB>& boxes);

 private:
  std::vector<int> ids_;  // user data: each object's body index
  std::vector<std::unique_ptr<coal::CollisionObject>> objects_;
  coal::DynamicAABBTreeCollisionManager manager_;
};

}  // namespace abd::contact
