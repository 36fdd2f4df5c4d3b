// One body's contact surface as three coal bounding-volume hierarchies, over its vertices,
// its edges and its triangles, built once from the rest shape (topology only).
//
// Two ways to world space. An affine body's motion x = A x̄ + p is not rigid, so coal's usual
// rigid-transform query would be wrong under shear/stretch; but the image of a rest box under
// the affine map is bounded in O(1) (bvh_traversal.h, TreeBoxes), so trees normally stay at
// rest and are never refit (the broad phase recovers A and p, affine_frame.h). A body whose
// map cannot be recovered is refit to world-space positions instead (O(n), tree topology
// kept; ABD bodies stay near-rigid, so the rest-shape topology stays a good tree). We use
// coal's beginUpdateModel/updateSubModel/endUpdateModel, which
// keeps the previous frame and fits each box around the primitive in both frames: updating
// to x0 then to x1 bounds the straight motion x0 → x1 (a linearly moving simplex stays in the
// convex hull of its end positions), and updating twice to x bounds x alone. (coal refuses
// beginReplaceModel once a model has been updated, so we never mix the two.)
//
// Why three trees: candidates are vertex–triangle and edge–edge pairs, so each kind of
// primitive needs its own leaves. Edges are stored as degenerate triangles (a, b, b), vertices
// as a point cloud; the trees are only traversed for their boxes (bvh_traversal.h), coal's
// narrow phase is never used on them. Leaves carry the primitive's own (local) index: coal
// does not reorder primitives.
#pragma once
#include <array>
#include <memory>
#include <vector>

#include <coal/BV/AABB.h>
#include <coal/BVH/BVH_model.h>

#include "common/types.h"

namespace abd::contact {

using Bvh = coal::BVHModel<coal::AABB>;

class BodyBvh {
 public:
  BodyBvh(const std::vector<Vec3>& rest, const std::vector<std::array<int, 2>>& edges,
          const std::vector<std::array<int, 3>>& faces);

  // The body's vertices at one time (static boxes).
  void refit(const std::vector<Vec3>& x);
  // The body's vertices moving linearly from x0 to x1 (swept boxes).
  void refit_swept(const std::vector<Vec3>& x0, const std::vector<Vec3>& x1);

  // Null when the body has no primitive of that kind (e.g. no triangles on a rod).
  const Bvh* vertices() const { return vertices_.get(); }
  const Bvh* edges() const { return edges_.get(); }
  const Bvh* faces() const { return faces_.get(); }

  // True until the first refit: the trees' boxes are those of the rest shape, which
  // TreeBoxes (bvh_traversal.h) maps to world space through the body's affine map.
  bool at_rest() const { return at_rest_; }

 private:
  void update_all(const std::vector<Vec3>& x);
  std::unique_ptr<Bvh> vertices_, edges_, faces_;
  bool at_rest_ = true;
};

}  // namespace abd::contact
