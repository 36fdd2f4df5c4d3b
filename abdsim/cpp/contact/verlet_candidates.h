// Broad-phase results reused across queries while the vertices stay near where they were
// (a Verlet list): the answer of BroadPhase::query / query_swept, exactly, for a fraction of
// the cost when bodies barely move between Newton iterations (a heap of 100 boxes spent a
// third of its time in the BVH descents, one swept query per iteration).
//
// Why it is exact. The list holds the BVH's candidates at centre positions x_c with the
// margin m_L = d̂ + 2δ. Take a later query (margin m <= d̂) whose positions (both ends, when
// swept) are each within δ of x_c. Every leaf box of that query (around the primitive's
// vertices, at both ends) lies inside the x_c leaf box grown by δ per axis, so a pair whose
// boxes come within m + r_a + r_b does at x_c within m + 2δ + r_a + r_b <= m_L + r_a + r_b:
// it is in the list. Filtering the list with the BVH's own leaf test (boxes_within on the
// primitives' boxes, the ground test on the lowest vertex) then yields the same set, in the
// same (sorted) order. Topological filters (shared vertices, contact table, fixed and
// scripted pairs) were applied when the list was built; the owner invalidates it when those
// change.
//
// Per body. The argument needs each vertex within δ of its own centre and each pair of the
// list found at the centres its two bodies have now, nothing more: a body whose vertices
// leave their centre gets a new one, and only its pairs are queried again (the BVH asked
// for that body alone, the others at their centres) and replace its old ones. A robot's
// slowly drifting trunk then re-queries the trunk, not every foot on the ground.
//
// Far moves. A body whose move is longer than 2δ (no centre covers both its ends) is not
// listed: the pairs that involve it come from a direct BVH query for those bodies alone
// (BroadPhaseQuery::bodies, at the real positions), the rest from the list, merged in the
// broad phase's sorted order. Its listed pairs are ignored until it is re-centred (at its
// next query, as a stale body). A heap's first Newton iteration of a step moves the falling
// boxes centimetres, the resting ones less than 2δ: those no longer re-query the whole scene.
#pragma once
#include <vector>

#include "contact/broad_phase/broad_phase.h"
#include "contact/contact_mesh.h"

namespace abd::contact {

class VerletCandidates {
 public:
  // reach: the largest margin served (d̂); slack: δ, how far a vertex may move from the
  // centre before the list is rebuilt.
  VerletCandidates(double reach, double slack) : reach_(reach), slack_(slack) {}

  // BroadPhase::query (x1 null) or query_swept (x0 → x1), from the list when it covers
  // them, otherwise from a new list centred on the move (or directly, for a move longer
  // than 2δ).
  Candidates query(BroadPhase& broad_phase, const ContactMesh& mesh, const std::vector<Vec3>& x0,
                   const std::vector<Vec3>* x1, const BroadPhaseQuery& q);

  void invalidate() { valid_ = false; }
  int rebuilds() const { return rebuilds_; }

 private:
  // Marks in `stale` the bodies with a vertex of x farther than δ from its centre.
  void mark_uncovered(const ContactMesh& mesh, const std::vector<Vec3>& x,
                      std::vector<char>& stale) const;
  // Centres body b's vertices on its move (its midpoint); false when some vertex moves
  // farther than 2δ (no centre covers it; the centres are then x0, a placeholder).
  bool recentre(const ContactMesh& mesh, int b, const std::vector<Vec3>& x0,
                const std::vector<Vec3>* x1);
  // New pairs for the stale_ bodies at the centres, replacing their old ones; false when
  // the query overflows.
  bool requery(BroadPhase& broad_phase, const ContactMesh& mesh, const BroadPhaseQuery& q);
  // The listed pairs within the query's margin at x0 (→ x1), but for those of far_ bodies.
  Candidates filter(const ContactMesh& mesh, const std::vector<Vec3>& x0,
                    const std::vector<Vec3>* x1, const BroadPhaseQuery& q) const;

  double reach_, slack_;
  bool valid_ = false;
  bool ground_ = false;
  double ground_height_ = 0.0;
  std::vector<Vec3> center_;
  std::vector<char> stale_;  // per body, scratch of query()
  // Per body: its move at the last query was too long for a centre; its listed pairs are
  // stale until it is re-centred.
  std::vector<char> far_;
  Candidates list_;
  int rebuilds_ = 0;
};

}  // namespace abd::contact
