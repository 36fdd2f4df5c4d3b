// Accepting or subdividing a solved step (World::step).
//
// Newton's iterates are each CCD-bounded, but the reported motion is the straight line from
// the state at t to the state at t + h, and Newton may reach the end by sliding one body
// around another: every iterate is intersection-free, yet the line between the two reported
// states crosses. A step is therefore accepted only if that line is itself free of contact
// (path_crosses, with the contact term's CCD) and no free body inverts or collapses (det A).
// A step that fails either test, or that Newton cannot solve, is redone in halves, halving
// again only the pieces that still fail, down to h / 2^kMaxDepth. Smaller pieces predict
// shorter moves, so colliding bodies meet within a piece and respond (bounce, push) at any
// speed and time step. Substeps are BDF1 steps; kinematic targets are interpolated linearly
// over the step.
#include <algorithm>
#include <sstream>
#include <string>

#include "common/affine.h"
#include "common/stopwatch.h"
#include "contact/ipc_contact_term.h"
#include "solver/bdf_history.h"
#include "solver/world.h"

namespace abd {
namespace {

// Pieces as small as h / 1024: a body crossing 100 times its size per step still meets the
// obstacle within a piece.
constexpr int kMaxDepth = 10;
// Refinement of the pieces everywhere (below) stops at depth 4: pieces of h / 8. Past that,
// refining did not clear the whole step's straight line in the heaps of issue 12 (a box
// turning round another's edge: the chords cut the corner at every depth; one step of the
// 100-box heap went on to 512 pieces, 42 s for nothing), while the steps that refinement did
// clear were cleared with pieces of h / 4. The last refinement is accepted even if that line
// crosses, as the h / 512 one was before (unchecked), and the step's substep_reason says so.
constexpr int kMaxRefinedDepth = 4;
// det A below which a free body may not shrink further (a collapse, e.g. crushed by a
// kinematic body).
constexpr double kMinDet = 1e-2;
// CCD restarts of a pair along the straight line: each keeps >= ccd_target (0.1) of its
// remaining gap, so a pair that still has not reached the end after this many closed its gap
// by a factor > 10^16: it touches or crosses.
constexpr int kCrossingRestarts = 16;
// A gap below this fraction of d̂ where a restart starts is contact (round-off), not a gap,
// whatever the CCD answers from there (it may pass through the surface: line_crosses).
constexpr double kTouchingGap = 1e-9;

struct SubstepState {
  VecX q0, q_dot0, q_prev0, q_dot_prev0, target;
  bool has_history0 = false;
  int pieces = 0;
  std::string last_failure;
  double last_piece = 0.0;  // length of the last committed piece
};

// `total` becomes the last piece's diagnostics, with the iteration counts and times summed
// and the CCD bound and the kinematic lag the extremes over the pieces. (Within the pieces,
// wall_time is the time of their solves; World::step sets the step's at the end.)
void accumulate(const StepDiagnostics& piece, StepDiagnostics& total) {
  const StepDiagnostics sums = std::move(total);
  total = piece;
  total.newton_iterations += sums.newton_iterations;
  total.total_body_iterations += sums.total_body_iterations;
  total.pcg_iterations += sums.pcg_iterations;
  total.wall_time += sums.wall_time;
  total.min_term_max_step = std::min(total.min_term_max_step, sums.min_term_max_step);
  total.driven_bodies = std::max(total.driven_bodies, sums.driven_bodies);
  if (sums.kinematic_lag > total.kinematic_lag) {
    total.kinematic_lag = sums.kinematic_lag;
    total.kinematic_lag_body = sums.kinematic_lag_body;
  }
}

// The iterations of work that was thrown away (a failed piece, a refinement round redone
// finer): counted into the step's diagnostics, so that they say what the step cost.
void add_iterations(const StepDiagnostics& from, StepDiagnostics& to) {
  to.newton_iterations += from.newton_iterations;
  to.total_body_iterations += from.total_body_iterations;
  to.pcg_iterations += from.pcg_iterations;
  to.wall_time += from.wall_time;
}

}  // namespace

std::string World::try_step(StepDiagnostics& d) {
  try {
    solve_step(d);
    std::string why = step_rejection();
    if (!why.empty() && undo_ballistic_shift()) {  // implicit Euler's own end, unshifted
      contact_diagnostics(d);
      why = step_rejection();
    }
    return why;
  } catch (const SolverError& e) {
    return e.what() + applied_tolerances();
  }
}

// The coupled solve holds bodies near contact to tighter tolerances than the settings (scaled
// to their size): a "did not converge" message quoting the settings' tolerances would show a
// last step that already meets them. Say which tolerance was actually applied (or will be
// after the friction refresh: the solve before it holds lagged bodies to 10 times looser ones).
std::string World::applied_tolerances() const {
  if (tol_translation_.size() != n_ || tol_affine_.size() != n_ || n_ == 0) return "";
  VecX tol_t = tol_translation_, tol_a = tol_affine_;
  if (tight_translation_.size() == n_ && tight_affine_.size() == n_) {
    tol_t = tol_t.cwiseMin(tight_translation_);
    tol_a = tol_a.cwiseMin(tight_affine_);
  }
  Eigen::Index bt = 0, ba = 0;
  const double t = tol_t.minCoeff(&bt), a = tol_a.minCoeff(&ba);
  if (t >= settings_.tol_translation && a >= settings_.tol_affine) return "";
  std::ostringstream os;
  os << "; the tolerances applied to bodies near contact are tighter than the settings: "
     << t << " m/s (" << describe(int(bt)) << "), " << a << " 1/s (" << describe(int(ba)) << ")";
  return os.str();
}

void World::remember_gap(const StepDiagnostics& d) {
  if (!contact_) return;
  gap_ = std::min(d.min_contact_distance, contact_->settings().d_hat);
  gap_q_ = q_;
  gap_kinematic_ = kinematic_;
}

bool World::path_crosses(const VecX& q0, const VecX& q1) const {
  if (!contact_) return false;
  const VecX dq = q1 - q0;
  // The distance between two primitives changes by at most the sum of their vertices'
  // displacements, and a vertex of body b moves by at most |Δp| + |ΔA|_F max|x̄|. If no two
  // bodies together move by half the smallest gap at q0 (known from the last commit, if q0
  // and the kinematic flags are still those), nothing can cross: no CCD needed. This skips
  // the swept query for resting and slowly moving contact.
  if (gap_q_.size() == q0.size() && gap_ > 0.0 && kinematic_ == gap_kinematic_ && gap_q_ == q0) {
    double largest = 0.0;
    for (int b = 0; b < n_; ++b) {
      const auto d = dq.segment<12>(12 * b);
      largest = std::max(largest, d.head<3>().norm() + d.tail<9>().norm() * extent_[b]);
    }
    if (2.0 * largest < 0.5 * gap_) return false;
  }
  // A restart from where the line has already closed in on a surface is contact: the CCD
  // finds no impact once the gap is at round-off (a box thrown through a slab: gap 1e-16 m
  // after 14 restarts, then "free"; an edge of the 20-box heap: 2.6e-17 m, then 0.70 of the
  // rest of the line, through a face), so a gap counts only where it is real.
  return contact_->line_crosses(q0, dq, kCrossingRestarts,
                                kTouchingGap * contact_->settings().d_hat);
}

std::string World::step_rejection() const {
  bool any_kinematic = false;
  for (int b = 0; b < n_; ++b) any_kinematic |= kinematic_[b] != 0;
  for (int b = 0; b < n_; ++b) {
    if (fixed_[b] || kinematic_[b]) continue;
    const double before = affine_A(q_.segment<12>(12 * b)).determinant();
    const double after = affine_A(x_.segment<12>(12 * b)).determinant();
    if (after > 0.0 && !(after < kMinDet && after < before)) continue;
    std::ostringstream os;
    os << describe(b) << " would " << (after > 0.0 ? "collapse" : "invert") << ": det A goes from "
       << before << " to " << after << " (the lowest allowed is " << kMinDet << ")";
    if (any_kinematic) os << "; a kinematic body may be crushing it (drive it less far)";
    return os.str();
  }
  if (path_crosses(q_, x_))
    return "the straight-line motion of the step crosses a contact surface (a body would pass "
           "through another between the reported states)";
  return "";
}

// q_prev_ is a piece ago, not a step: each body gets the history of a constant acceleration,
// its last piece's (bdf_history.h), so that the next step is BDF2 without a BDF1 restart (a
// body in free flight goes on along its parabola exactly). has_history_ stays as the last
// piece's commit left it: a piece that began or ended contact still restarts with BDF1.
void World::restart_history_after_pieces(double piece) {
  const double h = scene_.dt;
  for (int b = 0; b < n_; ++b) {
    const Vec12 v = q_dot_.segment<12>(12 * b);
    const Vec12 a = (v - q_dot_prev_.segment<12>(12 * b)) / piece;
    const bdf_history::State s =
        bdf_history::constant_acceleration(q_.segment<12>(12 * b), v, a, h);
    q_prev_.segment<12>(12 * b) = s.q;
    q_dot_prev_.segment<12>(12 * b) = s.q_dot;
  }
}

void World::advance_in_substeps(const std::string& failure, StepDiagnostics& d) {
  const double h = scene_.dt;
  SubstepState s{q_, q_dot_, q_prev_, q_dot_prev_, kinematic_target_, has_history_, 0, failure};
  StepDiagnostics total;
  // Iterations spent on work that was not kept: the whole step's failed attempt, failed
  // pieces, refinement rounds redone finer. They count in the step's totals.
  StepDiagnostics discarded;
  add_iterations(d, discarded);

  // Advances the state over [f0, f1] (fractions of the step) in one piece, or in halves
  // (always in halves above min_depth). A whole step that already failed as a BDF1 step is
  // not solved again as one piece (the same problem from the same state): it starts in halves,
  // i.e. at min_depth 2 (starting at 1 would make the first refinement round below a repeat
  // of the first: the same halves, solved again).
  int min_depth = d.integrator_order == 1 ? 2 : 1;
  auto advance = [&](auto&& self, double f0, double f1, int depth) -> bool {
    const double mid = 0.5 * (f0 + f1);
    if (depth < min_depth)
      return self(self, f0, mid, depth + 1) && self(self, mid, f1, depth + 1);
    scene_.dt = h * (f1 - f0);
    for (int b = 0; b < n_; ++b)
      if (kinematic_[b])
        kinematic_target_.segment<12>(12 * b) =
            s.q0.segment<12>(12 * b) +
            f1 * (s.target.segment<12>(12 * b) - s.q0.segment<12>(12 * b));
    has_history_ = false;  // pieces of different lengths: BDF1
    StepDiagnostics piece;
    piece.step = step_count_;
    const std::string why = timed(piece.wall_time, [&] { return try_step(piece); });
    if (why.empty()) {
      commit_step();
      remember_gap(piece);
      accumulate(piece, total);
      ++s.pieces;
      s.last_piece = scene_.dt;
      return true;
    }
    s.last_failure = why;
    add_iterations(piece, discarded);
    if (depth == kMaxDepth) return false;
    return self(self, f0, mid, depth + 1) && self(self, mid, f1, depth + 1);
  };
  // Pieces that are each free of crossings can still carry a body around another within the
  // step (it slid round it in a few long pieces): the reported motion, the straight line
  // over the whole step, would then cross. Finer pieces everywhere until it does not.
  for (; min_depth <= kMaxRefinedDepth; ++min_depth) {
    const StepDiagnostics start = total;
    s.pieces = 0;
    bool ok = advance(advance, 0.0, 1.0, 1);
    std::string note;
    if (ok && path_crosses(s.q0, q_)) {
      if (min_depth < kMaxRefinedDepth) {
        s.last_failure = "the pieces' motion carried a body through another over the whole step";
        ok = false;
      } else {
        note = "; the whole step's straight line still crosses after pieces of dt / " +
               std::to_string(1 << (kMaxRefinedDepth - 1)) +
               " everywhere (accepted: each piece's line is clear)";
      }
    }
    scene_.dt = h;
    kinematic_target_ = s.target;
    if (ok) {
      add_iterations(discarded, total);
      total.discarded_newton_iterations = discarded.newton_iterations;
      total.discarded_time = discarded.wall_time;
      restart_history_after_pieces(s.last_piece);
      total.substeps = s.pieces;
      total.substep_reason = failure + note;
      d = std::move(total);
      return;
    }
    q_ = s.q0;
    q_dot_ = s.q_dot0;
    q_prev_ = s.q_prev0;
    q_dot_prev_ = s.q_dot_prev0;
    has_history_ = s.has_history0;
    StepDiagnostics round;  // the committed pieces of this round, now undone
    round.newton_iterations = total.newton_iterations - start.newton_iterations;
    round.total_body_iterations = total.total_body_iterations - start.total_body_iterations;
    round.pcg_iterations = total.pcg_iterations - start.pcg_iterations;
    round.wall_time = total.wall_time - start.wall_time;
    add_iterations(round, discarded);
    total = start;
    if (s.pieces == 0 || s.last_failure.rfind("the pieces'", 0) != 0) break;
  }
  std::ostringstream os;
  os << "step " << step_count_ << " (t = " << time_ << ", dt = " << h << ") failed: " << failure
     << "; splitting it into pieces down to dt / " << (1 << kMaxDepth)
     << " did not help (last piece: " << s.last_failure << ")";
  throw SolverError(os.str());
}

}  // namespace abd
