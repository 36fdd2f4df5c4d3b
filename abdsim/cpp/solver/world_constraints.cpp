// The World's side of equality constraints (solver/constraint.h): which bodies they tie into
// islands, the projection of the Newton start onto c(q) = 0, and their violation.
#include <algorithm>
#include <cmath>

#include "common/same_bits.h"
#include "solver/world.h"

namespace abd {

namespace {
// A start off its constraints by less than this (m, or relative for directions) is left as
// it is: Newton steps keep linear rows where they are (to round-off), and a non-linear row
// (a prismatic joint on a moving parent) off by 1e-9 is three orders inside the 1e-6
// accuracy asked of joints. Projecting at every round-off residual cost one more KKT
// factorisation per Newton iteration.
constexpr double kProjectionTolerance = 1e-9;
constexpr int kMaxProjections = 20;
}  // namespace

void World::constraint_rows(const VecX& x, std::vector<ConstraintRow>& rows) const {
  rows.clear();
  for (const auto& c : constraints_) c->linearize(x, rows);
}

void World::newton_constraint_rows(std::vector<ConstraintRow>& rows) {
  if (projection_rows_valid_ && same_bits(projection_rows_x_, x_)) {
    rows.swap(projection_rows_);  // the next projection check refills projection_rows_
    projection_rows_valid_ = false;
    return;
  }
  if (same_bits(constraint_values_x_, x_)) {
    // The projection check's values at this x_ (the start, when it was on the constraints):
    // the same numbers linearize() would compute.
    rows.clear();
    for (std::size_t c = 0; c < constraints_.size(); ++c)
      constraints_[c]->linearize_with_values(
          x_, constraint_values_.data() + constraint_value_offsets_[c], rows);
    return;
  }
  constraint_rows(x_, rows);
}

// The movable bodies under a constraint this step.
void World::mark_jointed() {
  projection_rows_valid_ = false;  // a new step: rows of the last one are not reused
  constraint_values_x_.resize(0);
  jointed_.assign(n_, 0);
  nonlinear_constraints_ = false;
  for (const auto& c : constraints_) {
    c->mark_bodies(jointed_);
    nonlinear_constraints_ = nonlinear_constraints_ || !c->linear();
  }
  for (int b = 0; b < n_; ++b) jointed_[b] = jointed_[b] && movable_[b];
}

// Constrained bodies never take the free per-body solution (near), and bodies a constraint
// ties together are one island.
void World::join_constrained_islands(std::vector<unsigned char>& near) {
  if (constraints_.empty()) return;
  std::vector<BodyLink>& links = start_.constraint_links;  // kept: no allocation a step
  links.clear();
  for (const auto& c : constraints_) c->body_links(links);
  for (int b = 0; b < n_; ++b)
    if (jointed_[b]) near[b] = 1;
  for (const BodyLink& l : links)
    if (movable_[l.a] && movable_[l.b]) merge_islands(l.a, l.b);
}

// Moves x_ onto c = 0 with the least mass-weighted change of the movable bodies (the KKT
// solve with H = M and no force): exact in one solve for linear rows, Newton's method on the
// rows otherwise.
bool World::project_constraints(bool newton_step) {
  projection_rows_valid_ = false;
  if (constraints_.empty()) return false;
  auto moves = [&](int a, int b) { return (a >= 0 && jointed_[a]) || (b >= 0 && jointed_[b]); };
  // The check needs the values only: the rows (gradients) are built when x_ must move. All
  // of them at the start (kept for the first Newton solve's rows: newton_constraint_rows);
  // after a Newton step those of the rows that are not linear.
  std::vector<ConstraintValue>& values = constraint_values_;
  values.clear();
  constraint_value_offsets_.clear();
  for (const auto& c : constraints_) {
    constraint_value_offsets_.push_back(values.size());
    if (newton_step)
      c->nonlinear_values(x_, values);
    else
      c->values(x_, values);
  }
  if (newton_step)
    constraint_values_x_.resize(0);  // not every row's value: not for newton_constraint_rows
  else
    constraint_values_x_ = x_;
  double first = 0.0;
  for (const ConstraintValue& v : values)
    if (moves(v.body_a, v.body_b)) first = std::max(first, std::abs(v.value));
  if (!(first > kProjectionTolerance)) return false;
  std::vector<ConstraintRow>& rows = projection_rows_;  // kept: no reallocation per call
  auto worst = [&]() {
    double w = 0.0;
    for (const ConstraintRow& r : rows)
      if (moves(r.body_a, r.body_b)) w = std::max(w, std::abs(r.value));
    return w;
  };
  constraint_rows(x_, rows);
  std::vector<std::uint8_t> fixed(n_);
  for (int b = 0; b < n_; ++b) fixed[b] = !jointed_[b];
  VecX dx;
  const VecX zero = VecX::Zero(12 * n_);
  for (int k = 0; k < kMaxProjections && worst() > kProjectionTolerance; ++k) {
    system_.reset(n_, fixed);
    for (int b = 0; b < n_; ++b)
      system_.diagonal(b) = fixed[b] ? Mat12::Zero() : mass_matrix_[b];
    system_.finalize();
    kkt_projection_.solve(system_, rows, zero, dx);
    x_ += dx;
    constraint_rows(x_, rows);
  }
  projection_rows_x_ = x_;  // the rows at the final x_: the next Newton solve takes them
  projection_rows_valid_ = true;
  return true;
}

bool World::warm_guess(int b, double c2, Vec12& x) const {
  if (warm_valid_.size() != static_cast<std::size_t>(n_) || !warm_valid_[b]) return false;
  x = q_tilde_.segment<12>(12 * b) + c2 * warm_accel_.segment<12>(12 * b);
  return true;
}

void World::remember_warm_start(double c2) {
  warm_valid_.assign(n_, 0);
  warm_accel_.resize(12 * n_);
  for (int b = 0; b < n_; ++b) {
    if (!movable_[b] || driven_[b]) continue;
    warm_accel_.segment<12>(12 * b) = (x_.segment<12>(12 * b) - q_tilde_.segment<12>(12 * b)) / c2;
    warm_valid_[b] = 1;
  }
}

void World::constraint_diagnostics(StepDiagnostics& d) const {
  for (const auto& c : constraints_) {
    const ConstraintViolation v = c->violation(x_);
    d.joint_violation = std::max(d.joint_violation, v.position);
    d.joint_violation_angle = std::max(d.joint_violation_angle, v.angle);
  }
}

}  // namespace abd
