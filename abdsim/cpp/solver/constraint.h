// The interface of equality constraints c(q) = 0 on the stacked body state (joints, ...),
// the peer of EnergyTerm for what must hold exactly rather than be minimised. The Newton
// solver only sees rows: their values and gradients at q, each touching one or two bodies.
//
// How the World uses them (world_coupled.cpp): bodies a constraint ties together form one
// island that starts where it is; the start is projected onto c = 0 (mass-weighted least
// change) when it is off by more than round-off; every Newton direction solves the KKT system
// [H Jᵀ; J 0] [Δq; λ] = [−g; −c] (constrained_solve.h), so a linear constraint that holds at
// the start holds at every line-search trial. Constraints that are not linear (linear()
// false) are projected back onto c = 0 after every accepted iterate.
#pragma once
#include <string>
#include <vector>

#include "common/types.h"
#include "solver/energy_term.h"

namespace abd {

// One scalar constraint c(q) linearised at q: c + ja·Δq_a + jb·Δq_b. body_b = −1 for a
// constraint on one body (against the world).
struct ConstraintRow {
  int body_a = -1;
  int body_b = -1;
  Vec12 ja = Vec12::Zero();
  Vec12 jb = Vec12::Zero();
  double value = 0.0;
};

// One row's value at q and its bodies: what checking c(q) = 0 needs (no gradients).
struct ConstraintValue {
  int body_a = -1;
  int body_b = -1;
  double value = 0.0;
};

// How far q is from satisfying a constraint set: a distance (m) and an angle (rad).
struct ConstraintViolation {
  double position = 0.0;
  double angle = 0.0;
};

class Constraint {
 public:
  virtual ~Constraint() = default;
  virtual std::string name() const = 0;
  // Appends the rows at q (values and gradients).
  virtual void linearize(const VecX& q, std::vector<ConstraintRow>& rows) const = 0;
  // Appends the rows' values at q, in the order of linearize() (the same values). The
  // default linearizes; a constraint can skip the gradients.
  virtual void values(const VecX& q, std::vector<ConstraintValue>& out) const {
    std::vector<ConstraintRow> rows;
    linearize(q, rows);
    for (const ConstraintRow& r : rows) out.push_back({r.body_a, r.body_b, r.value});
  }
  // Appends the values at q of the rows that are not linear in q, in the order of
  // linearize(): a Newton step meets the linear rows exactly (to round-off), so after one
  // only these can be off c = 0. The default: every row's value.
  virtual void nonlinear_values(const VecX& q, std::vector<ConstraintValue>& out) const {
    if (!linear()) values(q, out);
  }
  // Appends the rows at q given their values there (`known`: this constraint's part of what
  // values(q) appended, in its order): a constraint whose gradients are constant copies
  // them and takes the values instead of computing them again. The default linearizes.
  virtual void linearize_with_values(const VecX& q, const ConstraintValue* /*known*/,
                                     std::vector<ConstraintRow>& rows) const {
    linearize(q, rows);
  }
  // True when every row is linear in q (its gradient does not depend on q).
  virtual bool linear() const { return true; }
  // Pairs of distinct bodies the constraints tie together, and bodies constrained at all
  // (marked[b] = 1; `marked` comes in sized to the number of bodies).
  virtual void body_links(std::vector<BodyLink>& links) const = 0;
  virtual void mark_bodies(std::vector<unsigned char>& marked) const = 0;
  virtual ConstraintViolation violation(const VecX& q) const = 0;
  // After every completed step, with the new state (e.g. to unwrap joint angles).
  virtual void end_step(const VecX& /*q*/, const VecX& /*q_dot*/) {}
};

}  // namespace abd
