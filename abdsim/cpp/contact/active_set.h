// The active set: every stencil whose primitives are within reach (d < d̂ + ξ) at one state q,
// built from broad-phase candidates by exact distances. The barrier is a sum over it. It is
// rebuilt by IpcContactTerm::update for each accepted Newton iterate, and on the fly for any
// other q the solver evaluates (line-search trials), so the energy at q is always the exact
// IPC energy at q.
#pragma once
#include <limits>
#include <vector>

#include "contact/broad_phase/broad_phase.h"
#include "contact/contact_stencil.h"
#include "contact/contact_table.h"

namespace abd::contact {

struct ActiveSet {
  VecX q;                                // the state it describes
  std::vector<Vec3> x;                   // world positions of every vertex at q
  std::vector<ContactStencil> stencils;  // in candidate order: point–triangle, edge–edge, ground
  // Each stencil's squared distance at x and feasibility, as selecting it found them: the
  // energy at this q reuses them instead of computing every distance a second time.
  std::vector<StencilDistance> distances;
  // Smallest gap d − ξ among the stencils (+inf without any); negative or zero if infeasible.
  double min_gap = std::numeric_limits<double>::infinity();
  int infeasible = -1;                   // index of the first infeasible stencil, or -1
};

// Keeps the candidates whose gap d − ξ is below `reach`.
ActiveSet select_active(const ContactMesh& mesh, const ContactTable& table,
                        const Candidates& candidates, VecX q, std::vector<Vec3> x, double reach,
                        double ground_height);

}  // namespace abd::contact
