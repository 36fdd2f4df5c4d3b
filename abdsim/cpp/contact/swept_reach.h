// Which of a sweep's candidate pairs can come within reach at a line-search trial.
//
// The step-bound sweep (ipc_contact_sweep.cpp) collects every pair whose boxes come within
// d̂ anywhere on the move x0 → x0 + Δ; most never come near (the boxes are loose). A trial
// moves each body b part of the way, x0 + t_b Δ (t_b in [0, 1], vertices are linear in q).
// Every point of a primitive is a fixed convex combination of its vertices, so it moves by at
// most its largest vertex move; after removing any common translation c (distances do not
// see it), the gap of a pair at (t_a, t_b) is at least
//     gap0 − t_a max_i |Δa_i − c| − t_b max_j |Δb_j − c| − |t_a − t_b| |c|
// (c: the mean vertex move, as additive CCD takes it). Pairs whose bound stays at or above
// reach (plus a slack far above rounding) cannot be in the active set at the trial, so the
// active set is selected from the rest only: the same stencils, in the same order, as from
// all candidates (the energy is bit-identical), without their distances at every trial.
#pragma once
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "contact/broad_phase/broad_phase.h"
#include "contact/contact_stencil.h"

namespace abd::contact {

struct PathReach {
  double gap0 = 0.0;   // d − ξ at x0 (signed above the ground); -inf: keep always
  double move_a = 0.0;  // max_i |Δa_i − c| over the first side's vertices
  double move_b = 0.0;  // the same over the second side (0 for the ground)
  double common = 0.0;  // |c|
  double slack = 0.0;   // rounding allowance of this pair (besides the relative one)
  std::array<int, 2> bodies{-1, -1};
};

// The bound's data of stencil s from the vertices x0 at the sweep's start and p1 at the end of
// each side's checked move. gap0 is the distance select_active would compute at x0, or
// known_gap (the same to rounding, e.g. additive CCD's) when that is not NaN.
PathReach path_reach(const ContactStencil& s, const std::vector<Vec3>& x0,
                     const std::array<Vec3, 4>& p1, double ground_height,
                     double known_gap = std::numeric_limits<double>::quiet_NaN());

// The same from what the sweep's CCD computed along the pair's one checked move (both sides
// moving by one fraction of their move, p1 as above): its gap d − ξ at x0 and its moves
// (CcdOptions::moves), which are path_reach's to the bit, without computing them again.
PathReach path_reach_from_ccd(const ContactStencil& s, const std::vector<Vec3>& x0, double gap0,
                              double move_a, double move_b, double common);

// The lowest gap the bound allows with the two sides at t_a and t_b of their moves.
inline double lowest_gap(const PathReach& r, double ta, double tb) {
  return r.gap0 - ta * r.move_a - tb * r.move_b - std::abs(ta - tb) * r.common - r.slack;
}

// The candidates (in their order) whose bound reaches below `reach` with body b at t[b] of its
// move (the ground: 0). `reach_of` holds one PathReach per candidate, in the order
// point–triangle, edge–edge, point–ground.
void reachable_candidates(const Candidates& all, const std::vector<PathReach>& reach_of,
                          const std::vector<double>& t, double reach, Candidates& out);

}  // namespace abd::contact
