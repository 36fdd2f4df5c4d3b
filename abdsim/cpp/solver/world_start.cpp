// Where the coupled solve starts (world_coupled.cpp, steps 1 and 2): kinematic bodies at
// their targets or driven, free solutions of the bodies nothing comes near, warm guesses of
// jointed islands, everything else where it is.
#include <algorithm>
#include <numeric>
#include <vector>

#include "common/affine.h"
#include "solver/body_math.h"
#include "solver/parallel.h"
#include "solver/world.h"
#include "solver/world_detail.h"

namespace abd {
using namespace world_detail;

// Kinematic bodies: at their targets (constrained) when the move is free of contact with
// everything else at rest; otherwise driven (movable, pulled by the stiff spring).
void World::place_kinematic_bodies(StepDiagnostics& d) {
  VecX& dq = start_.dq;
  dq.setZero(12 * n_);
  bool any = false;
  for (int b = 0; b < n_; ++b) {
    if (!kinematic_[b]) continue;
    const Vec12 step = q_tilde_.segment<12>(12 * b) - q_.segment<12>(12 * b);
    if (step.isZero(0.0)) continue;
    dq.segment<12>(12 * b) = step;
    any = true;
  }
  std::vector<unsigned char>& moving = start_.moving;
  std::vector<unsigned char>& near = start_.near;
  std::vector<BodyLink>& links = start_.links;
  moving.assign(n_, 0);
  links.clear();
  while (any) {
    for (int b = 0; b < n_; ++b) moving[b] = !dq.segment<12>(12 * b).isZero(0.0);
    const double global = step_bounds(q_, dq, moving, near, links);
    bool blocked = false;
    for (int b = 0; b < n_; ++b) {
      if (!moving[b] || std::min(bound_[b], global) >= 1.0) continue;
      driven_[b] = 1;
      constrained_[b] = 0;
      dq.segment<12>(12 * b).setZero();
      blocked = true;
    }
    if (!blocked) break;
    any = !dq.isZero(0.0);
  }
  for (int b = 0; b < n_; ++b) {
    if (constrained_[b] && kinematic_[b]) x_.segment<12>(12 * b) = q_tilde_.segment<12>(12 * b);
    if (driven_[b]) {
      x_free_.segment<12>(12 * b) = q_tilde_.segment<12>(12 * b);  // head for the target
      ++d.driven_bodies;
    }
  }
}

// The Newton start. Every movable body is checked on its way to its warm guess, else its
// prediction x̃ (the target for driven bodies). Bodies that nothing comes near on that move
// (no term reaches them within d̂) run the per-body Newton solve of the fast path and keep
// its free solution. They are done (frozen) when no contact pair involves them there (the
// energy of the terms is zero around it: it is the solution) and their path to it is clear:
// the checked one, when the solution lies within d̂/4 of where that move ended (so the path
// stays farther than d̂/2 from everything), else their own move, checked again against
// everything else at its start. Every island with something near starts at its warm
// guesses when the whole move there is clear, else where it is (IPC's start, always
// feasible): a start clipped by CCD short of its target would sit deep in the barrier,
// where Newton on a log barrier only creeps back out.
void World::start_iterate(bool split, double c2, StepDiagnostics& d) {
  // Bodies head for their warm guess (warm_guess; bodies without one, for their prediction):
  // islands start there when that move is feasible (every step bound 1), else where they
  // are. A resting heap of 100 boxes starts within ~2 tolerances of its solution this way
  // (~100 from where it is): 1-4 Newton iterations a step instead of 6-10.
  head_for_warm_guesses(c2);
  if (!split) join_movable_bodies();
  check_start_moves();
  solve_free_bodies(split, c2, d);
  const bool all_clear = place_start(split, d);
  recheck_warm_islands();
  start_terms(all_clear);
  if (split) freeze_free_islands();
}

// Where each movable body heads first (x_free_): its warm guess, else its prediction
// (orthogonalised, predict_body); dq_ the move there from x_.
void World::head_for_warm_guesses(double c2) {
  mark_jointed();
  // The predictions bodies may start from (or solve alone from) are orthogonalised: all but
  // those of jointed bodies with a warm guess, which start there.
  const bool any_warm_guess = warm_valid_.size() == static_cast<std::size_t>(n_);
  parallel_for(n_, threads_, [&](int b) {
    if (fixed_[b] || kinematic_[b] || (any_warm_guess && warm_valid_[b] && jointed_[b])) return;
    orthogonalise_prediction(b);
    x_free_.segment<12>(12 * b) = x_pred_.segment<12>(12 * b);
  });
  std::vector<unsigned char>& warm = start_.warm;
  warm.assign(n_, 0);
  for (int b = 0; b < n_; ++b) {
    if (!movable_[b] || driven_[b]) continue;
    Vec12 guess;
    warm[b] = warm_guess(b, c2, guess);
    if (warm[b]) x_free_.segment<12>(12 * b) = guess;
  }
  dq_.setZero(12 * n_);
  for (int b = 0; b < n_; ++b)
    if (movable_[b]) dq_.segment<12>(12 * b) = x_free_.segment<12>(12 * b) - x_.segment<12>(12 * b);
}

// Terms that do not split by body couple everything: the movable bodies are one island.
void World::join_movable_bodies() {
  int first = -1;
  for (int b = 0; b < n_; ++b)
    if (movable_[b]) {
      if (first < 0)
        first = b;
      else
        merge_islands(first, b);
    }
}

// The step bounds of the move x_ → x_ + dq_: the islands its links and the constraints form,
// which of them may start at their warm guesses (warm_island) and which stay where they are
// (stays: something comes near, or the move is cut).
void World::check_start_moves() {
  std::vector<unsigned char>& near = start_.near;
  std::vector<BodyLink>& links = start_.links;
  links.clear();
  start_.global = step_bounds(x_, dq_, movable_, near, links);
  // The checks so far (the last check of a move is skipped when one of them was that move;
  // kept only where that last check can run: some term has a reach).
  start_.reach = 0.0;
  for (const auto& t : terms_) start_.reach = std::max(start_.reach, t->reach());
  start_.checked.clear();
  if (start_.reach > 0.0) start_.checked.push_back({x_, dq_, bound_, start_.global});
  for (const BodyLink& l : links) merge_islands(l.a, l.b);
  join_constrained_islands(near);
  const double global = start_.global;
  std::vector<unsigned char>& warm_island = start_.warm_island;  // per island root
  warm_island.assign(n_, 1);
  for (int b = 0; b < n_; ++b)
    if (movable_[b] && !(start_.warm[b] && bound_[b] >= 1.0 && global >= 1.0))
      warm_island[island(b)] = 0;
  std::vector<unsigned char>& stays = start_.stays;  // per island root: start where it is
  stays.assign(n_, 0);
  for (int b = 0; b < n_; ++b)
    if (movable_[b] && (near[b] || bound_[b] < 1.0 || global < 1.0)) stays[island(b)] = 1;
}

// Free solutions (x_free_, solved) of the bodies of islands that nothing comes near; when
// one strays from the checked path, the solved bodies' own moves are checked again.
void World::solve_free_bodies(bool split, double c2, StepDiagnostics& d) {
  const std::vector<unsigned char>& warm = start_.warm;
  std::vector<unsigned char>& warm_island = start_.warm_island;
  std::vector<unsigned char>& stays = start_.stays;
  const double slack = 0.25 * start_.reach;
  free_iterations_.assign(n_, 0);
  std::vector<unsigned char>& solved = start_.solved;
  std::vector<unsigned char>& strayed = start_.strayed;
  solved.assign(n_, 0);
  strayed.assign(n_, 0);
  for (int b = 0; b < n_; ++b) solved[b] = split && movable_[b] && !driven_[b] && !stays[island(b)];
  parallel_for(n_, threads_, [&](int b) {
    if (!solved[b]) return;
    Vec12 x = x_pred_.segment<12>(12 * b);
    BodyNewton r;
    newton_body(b, c2, x, r, nullptr);
    free_iterations_[b] = r.iterations;
    // Measured from the end of the checked move (the warm guess, else the prediction).
    const Vec12 dev = x - x_free_.segment<12>(12 * b);
    const double moved = dev.head<3>().norm() + extent_[b] * affine_A(dev).norm();
    if (r.status != kConverged) {
      solved[b] = 0;
    } else {
      x_free_.segment<12>(12 * b) = x;
      strayed[b] = moved > slack;
    }
  });
  bool recheck = false;
  for (int b = 0; b < n_; ++b) {
    d.total_body_iterations += free_iterations_[b];
    recheck = recheck || (solved[b] && strayed[b]);
  }
  if (recheck) {
    // Some free solutions strayed from the checked path: check the solved bodies' own moves
    // with the jointed islands' moves to their warm guesses (everything else where it
    // starts); a warm island whose move is no longer clear starts where it is.
    dq_.setZero(12 * n_);
    for (int b = 0; b < n_; ++b)
      if (solved[b] || (warm[b] && warm_island[island(b)]))
        dq_.segment<12>(12 * b) = x_free_.segment<12>(12 * b) - x_.segment<12>(12 * b);
    std::vector<unsigned char> near2;
    std::vector<BodyLink> links2;
    const double global2 = step_bounds(x_, dq_, movable_, near2, links2);
    if (start_.reach > 0.0) start_.checked.push_back({x_, dq_, bound_, global2});
    for (int b = 0; b < n_; ++b) {
      if (solved[b] && (near2[b] || bound_[b] < 1.0)) solved[b] = 0;
      if (warm[b] && (bound_[b] < 1.0 || global2 < 1.0)) warm_island[island(b)] = 0;
    }
  }
  for (int b = 0; b < n_; ++b)
    if (split && movable_[b] && !driven_[b] && !stays[island(b)] && !solved[b])
      stays[island(b)] = 1;  // its free solution failed, or its own move comes near
}

// x_ at the start: islands that do not stay, and warm islands, at x_free_; the others where
// they are. True when every movable body was solved alone (no contact pair anywhere).
bool World::place_start(bool split, StepDiagnostics& d) {
  bool all_clear = split;
  for (int b = 0; b < n_; ++b) {
    if (!movable_[b]) continue;
    const double bound = std::min(bound_[b], start_.global);
    d.min_term_max_step = std::min(d.min_term_max_step, bound);
    const int r = island(b);
    if (!start_.stays[r] || start_.warm_island[r]) x_.segment<12>(12 * b) = x_free_.segment<12>(12 * b);
    all_clear = all_clear && start_.solved[b];
  }
  return all_clear;
}

// The warm islands' moves were checked with the other bodies moving too: check them once
// more against where everything else now starts (only terms with a reach can object); an
// island whose move is not clear starts where it is.
void World::recheck_warm_islands() {
  const std::vector<unsigned char>& warm = start_.warm;
  std::vector<unsigned char>& warm_island = start_.warm_island;
  auto warm_start = [&](int b) { return movable_[b] && warm[b] && warm_island[island(b)]; };
  bool any_warm = false;
  for (int b = 0; b < n_; ++b) any_warm = any_warm || warm_start(b);
  if (!any_warm || !(start_.reach > 0.0)) return;
  VecX from = x_;
  dq_.setZero(12 * n_);
  for (int b = 0; b < n_; ++b)
    if (warm_start(b)) {
      from.segment<12>(12 * b) = q_.segment<12>(12 * b);
      dq_.segment<12>(12 * b) = x_.segment<12>(12 * b) - q_.segment<12>(12 * b);
    }
  // Often the very move checked first (every moving body is warm: a robot on the ground),
  // whose bounds stand; otherwise it is checked now.
  double global3 = 1.0;
  const auto same = std::find_if(start_.checked.begin(), start_.checked.end(),
                                 [&](const StartScratch::CheckedMove& c) {
                                   return c.from == from && c.dq == dq_;
                                 });
  if (same != start_.checked.end()) {
    bound_ = same->bound;
    global3 = same->global;
  } else {
    std::vector<unsigned char> near3;
    std::vector<BodyLink> links3;
    global3 = step_bounds(from, dq_, movable_, near3, links3);
  }
  for (int b = 0; b < n_; ++b)
    if (warm_start(b) && (bound_[b] < 1.0 || global3 < 1.0)) warm_island[island(b)] = 0;
  for (int b = 0; b < n_; ++b)
    if (movable_[b] && warm[b] && !warm_island[island(b)] && start_.stays[island(b)])
      x_.segment<12>(12 * b) = q_.segment<12>(12 * b);
}

// The start onto the constraints, the terms at the start (update_clear when no contact pair
// can exist), and the islands the terms link there.
void World::start_terms(bool all_clear) {
  project_constraints(false);  // constrained bodies start where they are: on c = 0
  for (const auto& t : terms_) {
    if (all_clear)
      t->update_clear(x_);  // what update() would find, without the proximity query
    else
      t->update(x_);
  }
  std::vector<BodyLink>& links = start_.links;
  links.clear();
  for (const auto& t : terms_) t->body_links(movable_, links);
  for (const BodyLink& l : links) merge_islands(l.a, l.b);
}

// Islands with nothing near, at their free solution, with no contact there: solved.
void World::freeze_free_islands() {
  std::vector<unsigned char>& engaged = start_.engaged;
  engaged.assign(n_, 0);
  for (const auto& t : terms_) t->mark_active_bodies(engaged);
  std::vector<unsigned char>& free_island = start_.free_island;
  free_island.assign(n_, 1);
  for (int b = 0; b < n_; ++b)
    if (movable_[b] && (start_.near[b] || start_.stays[island(b)] || !start_.solved[b] ||
                        engaged[b]))
      free_island[island(b)] = 0;
  for (int b = 0; b < n_; ++b)
    if (movable_[b] && free_island[island(b)]) frozen_[b] = converged_[b] = 1;
}

// Lagged quantities (friction's normal forces and bases) at the Newton start rather than at
// q_t, when the two differ: islands start at their warm guess, close to the
// solution, so the first iterate already sees the forces it converges to and the friction
// iteration after convergence (refresh_lagged there) mostly finds nothing to change (go2
// standing: Newton iterations per step 2.13 -> 1.30). Still one lagged state per step.
void World::lag_at_start() {
  if (x_ == q_) return;
  bool changed = false;
  for (const auto& t : terms_) changed = t->refresh_lagged(x_) || changed;
  if (!changed) return;
  // The bodies that rub now converge to friction's tolerances too (limit_tolerances only
  // tightens).
  for (const auto& t : terms_) t->limit_tolerances(tol_translation_, tol_affine_, radius_);
}

}  // namespace abd
