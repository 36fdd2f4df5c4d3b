// BDF1's free flight made exact (World::shift_ballistic_bodies).
//
// Implicit Euler puts a falling body ½ h² g below its parabola at every step: q_{t+1} =
// q_t + h q̇_t + h² g_q against the exact q_t + h q̇_t + ½ h² g_q, while the velocity it reports,
// q̇_t + h g_q, is exact. At the default h = 1e-2 a ball dropped 5 cm rebounded 18–24 % lower
// than e² says, all of it lost in flight (MuJoCo's Euler loses the same).
//
// For a body that no term and no constraint pushes at the solution, the step's minimiser is
// the free one, argmin ½|x − q̃|²_M + h² Ψ(A), and Ψ does not depend on p: taking q̃'s gravity
// as ½ h² g_q instead of h² g_q moves that minimiser by exactly −½ h² g_q (translation only)
// and, with the velocity (x − q_t)/h + ½ h g_q, leaves the velocity as it is. Such bodies are
// shifted after the solve, so their translation follows the parabola exactly and their energy
// is conserved; bodies in contact, jointed, scripted or pushed by any term keep implicit Euler
// (a resting body stays at rest). The shifted step is checked like any other
// (step_rejection); if it is not clear, the shift is undone (World::try_step).
#include "solver/world.h"

namespace abd {

void World::shift_ballistic_bodies() {
  ballistic_.assign(n_, 0);
  std::vector<unsigned char> forced(n_, 0);
  for (const auto& c : constraints_) c->mark_bodies(forced);
  for (const auto& t : terms_) t->mark_forced_bodies(forced);
  const Vec3 drop = 0.5 * scene_.dt * scene_.dt * scene_.gravity;
  if (drop.isZero(0.0)) return;
  for (int b = 0; b < n_; ++b) {
    if (!dynamic_[b] || fixed_[b] || kinematic_[b] || external_kinetic_[b] || forced[b]) continue;
    ballistic_[b] = 1;
    x_.segment<3>(12 * b) -= drop;
  }
}

bool World::undo_ballistic_shift() {
  if (ballistic_.size() != static_cast<std::size_t>(n_)) return false;
  const Vec3 drop = 0.5 * scene_.dt * scene_.dt * scene_.gravity;
  bool any = false;
  for (int b = 0; b < n_; ++b) {
    if (!ballistic_[b]) continue;
    x_.segment<3>(12 * b) += drop;
    ballistic_[b] = 0;
    any = true;
  }
  return any;
}

}  // namespace abd
