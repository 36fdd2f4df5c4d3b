// A body's affine map x = A x̄ + p recovered from its world vertices, so that the broad phase
// can bound a BVH node's world box from the node's rest box (affine_box.h) instead of refitting
// the whole tree to the vertices at every query.
//
// Why recover and not receive (A, p): the broad phase is handed world vertices only (the
// contact term's callers compute them from q with ContactMesh::world_vertices). Four rest
// vertices spanning a well-shaped tetrahedron determine A and p exactly (up to rounding); a few
// more rest vertices (the extremes along each axis) are checked against the recovered map, so
// positions that are not an affine image of the rest shape are detected and the caller falls
// back to refitting. A body whose vertices do not span 3D well (a flat plate, a rod, a point)
// has no frame and is always refit.
#pragma once
#include <array>
#include <vector>

#include "common/types.h"

namespace abd::contact {

struct AffineMap {
  Mat3 A = Mat3::Identity();
  Vec3 p = Vec3::Zero();
  double pad = 0.0;  // absolute slack (m) covering the recovery's rounding
};

class AffineFrame {
 public:
  // rest: the body's rest vertices x̄.
  explicit AffineFrame(const std::vector<Vec3>& rest);

  bool valid() const { return valid_; }

  // The map taking rest[i] to x[i] (x: the body's first world vertex). False when the body has
  // no frame, or when a checked vertex is off the recovered map by more than its slack.
  bool recover(const Vec3* x, AffineMap& out) const;

 private:
  bool valid_ = false;
  std::array<int, 4> ref_{};       // the tetrahedron's vertices
  Mat3 inv_edges_ = Mat3::Zero();  // inverse of [x̄1 − x̄0, x̄2 − x̄0, x̄3 − x̄0]
  std::vector<int> checks_;        // vertices checked against the map
  std::vector<Vec3> rest_checks_;  // their rest positions
  Vec3 rest_ref0_ = Vec3::Zero();
  double rest_radius_ = 0.0;  // largest |x̄ − x̄0|
};

}  // namespace abd::contact
