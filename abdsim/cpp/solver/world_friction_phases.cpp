// The coupled solve's two phases around a friction iteration (world_coupled.cpp, IPC's
// friction iterations): Newton converges, terms re-evaluate what they lagged (friction's
// normal forces and tangent bases) at that solution, and Newton goes on to the solution of
// the new lagged state.
//
// The first solve only says where to lag: its answer is replaced by the second's. Its bodies
// with lagged terms therefore converge to tolerances kLooseFactor looser than the tight ones
// those terms ask for (limit_tolerances: friction's 0.1 ε_v, 1e-4 m/s at the defaults; at
// most the settings'), and every such body converges to the tight ones after the refresh.
// Newton often converges linearly at the end (projected barrier Hessians drop a negative
// mode), so the first solve's last iterations are saved.
#include <algorithm>

#include "solver/world.h"

namespace abd {
namespace {

// Not looser: the lagged normal forces are the barrier's gradient, stiff in the gap, and a
// first solve converged to the settings' 0.01 m/s (100 times friction's tolerance) lagged
// them off by up to 13%: a box sliding from inside the barrier (μ = 0.1) lost 1.127 μ g h in
// its first step instead of 1.0015 (tests/contact/test_friction_phases.py); 10 times: 1.0021.
constexpr double kLooseFactor = 10.0;

}  // namespace

void World::loosen_lagged_tolerances() {
  loose_phase_ = false;
  unfinished_.assign(n_, 0);
  tight_translation_ = tol_translation_;
  tight_affine_ = tol_affine_;
  if (settings_.friction_iterations == 0) return;  // no second solve: the first is the answer
  std::vector<unsigned char>& lagged = loose_;
  lagged.assign(n_, 0);
  for (const auto& t : terms_) t->mark_lagged_bodies(lagged);
  for (int b = 0; b < n_; ++b) {
    if (!lagged[b] || !movable_[b]) continue;
    loose_phase_ = loose_phase_ || tol_translation_[b] < settings_.tol_translation ||
                   tol_affine_[b] < settings_.tol_affine;
    tol_translation_[b] = std::min(kLooseFactor * tol_translation_[b],
                                   std::max(tol_translation_[b], settings_.tol_translation));
    tol_affine_[b] =
        std::min(kLooseFactor * tol_affine_[b], std::max(tol_affine_[b], settings_.tol_affine));
  }
}

void World::note_tight_convergence(int b, double st, double sa) {
  if (!loose_phase_) return;
  // 1 + ν: a damped island's undamped step is at most that much longer (world_coupled.cpp).
  const double ratio = std::max(st / tight_translation_[b], sa / tight_affine_[b]) *
                       (1.0 + damping_[island(b)]);
  unfinished_[b] = ratio > 1.0;
}

bool World::retighten_after_refresh(bool changed) {
  const bool loose = loose_phase_;
  loose_phase_ = false;
  if (!changed && !loose) return false;
  std::vector<unsigned char> again(n_, 0);
  if (changed) {
    // The bodies the refresh changed iterate again, to the tolerances of the new lagged state.
    for (const auto& t : terms_) t->mark_lagged_bodies(again);
  }
  if (loose) {
    tol_translation_ = tight_translation_;
    tol_affine_ = tight_affine_;
    // An island is as converged as its least converged body.
    std::vector<unsigned char> island_unfinished(n_, 0);
    for (int b = 0; b < n_; ++b)
      if (movable_[b] && loose_[b] && unfinished_[b]) island_unfinished[island(b)] = 1;
    for (int b = 0; b < n_; ++b)
      if (movable_[b] && island_unfinished[island(b)]) again[b] = 1;
  }
  if (changed) {
    VecX tol_t = tol_translation_, tol_a = tol_affine_;
    for (const auto& t : terms_) t->limit_tolerances(tol_t, tol_a, radius_);
    for (int b = 0; b < n_; ++b) {
      if (!again[b] || !movable_[b]) continue;
      tol_translation_[b] = tol_t[b];
      tol_affine_[b] = tol_a[b];
    }
  }
  bool any = false;
  for (int b = 0; b < n_; ++b) {
    if (!again[b] || !movable_[b]) continue;
    frozen_[island(b)] = converged_[island(b)] = 0;
    any = true;
  }
  return any;
}

}  // namespace abd
