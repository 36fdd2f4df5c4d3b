// The coupled solve's line search (world_coupled.cpp, step 3): Armijo backtracking on Π per
// island from x_ along dq_, every island tried at once per evaluation of Π (one contact query
// per trial), and what the step taken says about each island afterwards (convergence,
// Levenberg–Marquardt damping).
#include <algorithm>

#include "solver/world.h"
#include "solver/world_detail.h"

namespace abd {
using namespace world_detail;

// Each island's Π at x_ (from body_E_ and `rest`) and its slope along dq_.
void World::sum_islands(bool split, double rest, const std::vector<std::uint8_t>& inactive,
                        int rest_root) {
  island_E_.setZero(n_);
  island_slope_.setZero(n_);
  for (int b = 0; b < n_; ++b) {
    if (inactive[b]) continue;
    const int r = island(b);
    island_E_[r] += body_E_[b];
    island_slope_[r] += grad_.segment<12>(12 * b).dot(dq_.segment<12>(12 * b));
  }
  // Terms that do not split couple everything: a single island carries their energy.
  if (!split && rest_root >= 0) island_E_[rest_root] += rest;
}

int World::armijo_search_islands(double c2, bool split, double rest,
                                 std::vector<std::uint8_t>& inactive, double& rest_new,
                                 StepDiagnostics& d) {
  int rest_root = -1;
  for (int b = 0; b < n_ && rest_root < 0; ++b)
    if (movable_[b]) rest_root = island(b);
  sum_islands(split, rest, inactive, rest_root);
  auto try_alphas = [&](std::vector<BodyLink>& links) {  // trial_ and its Π
    trial_ = x_;
    for (int b = 0; b < n_; ++b)
      if (!inactive[b]) trial_.segment<12>(12 * b) += alpha_[island(b)] * dq_.segment<12>(12 * b);
    links.clear();
    rest_new = body_energies(trial_, c2, body_E_new_, links);
  };

  std::vector<BodyLink> links;
  rest_new = rest;
  bool failed = false;
  for (int ls = 0; ls <= settings_.max_line_search_iterations; ++ls) {
    try_alphas(links);
    bool merged = false;
    for (const BodyLink& l : links) merged = merge_islands(l.a, l.b) || merged;
    if (merged) {  // not expected (the step bounds linked every pair in reach): start over
      for (int b = 0; b < n_; ++b) inactive[b] = !(movable_[b] && !frozen_[island(b)]);
      sum_islands(split, rest, inactive, rest_root);
      continue;
    }
    island_E_new_.setZero(n_);
    for (int b = 0; b < n_; ++b)
      if (!inactive[b]) island_E_new_[island(b)] += body_E_new_[b];
    if (!split && rest_root >= 0) island_E_new_[rest_root] += rest_new;
    bool any_pending = false;
    for (int r = 0; r < n_; ++r) {
      if (inactive[r] || island(r) != r || !pending_[r]) continue;
      const double E0 = island_E_[r];
      if (island_E_new_[r] <= E0 + settings_.armijo_c * alpha_[r] * island_slope_[r] +
                                  roundoff(E0)) {
        pending_[r] = 0;
      } else if (ls == settings_.max_line_search_iterations) {
        failed = true;
      } else {
        alpha_[r] *= 0.5;
        halved_[r] = 1;
        ++d.line_search_halvings;
        any_pending = true;
      }
    }
    if (!any_pending) break;
  }
  if (!failed) return -1;
  // A converged island whose step does not decrease Π just stays; any other fails.
  for (int r = 0; r < n_; ++r) {
    if (inactive[r] || island(r) != r || !pending_[r]) continue;
    if (!converged_[r]) return r;
    alpha_[r] = 0.0;
    pending_[r] = 0;
  }
  try_alphas(links);
  return -1;
}

void World::judge_island_steps(const std::vector<std::uint8_t>& inactive,
                               const VecX& island_ratio, StepDiagnostics& d) {
  // A small direction only proves convergence when the island took it whole: a step the
  // CCD bound or Armijo shortened says the model is off there. Exceptions: alpha 0 (a
  // converged island whose step no longer decreases Π: round-off) and directions a
  // hundred times below tolerance (bounds and Armijo tests are noise at that size).
  for (int r = 0; r < n_; ++r)
    if (!inactive[r] && island(r) == r && alpha_[r] > 0.0 && alpha_[r] < 1.0 &&
        island_ratio[r] * (1.0 + damping_[r]) > kRoundoffStep)
      converged_[r] = 0;
  double min_alpha = 1.0;
  for (int r = 0; r < n_; ++r)
    if (!inactive[r] && island(r) == r) min_alpha = std::min(min_alpha, alpha_[r]);
  d.line_search_alphas.push_back(min_alpha);
  // Levenberg–Marquardt damping per island (ν M added to the Newton matrix): raised when
  // Armijo had to cut the step (the quadratic model overshot, typically a soft rotation
  // of a body on few contacts), relaxed when it did not. An island only converges
  // undamped.
  for (int r = 0; r < n_; ++r) {
    if (inactive[r] || island(r) != r) continue;
    if (halved_[r])
      damping_[r] = damping_[r] > 0.0 ? std::min(2.0 * damping_[r], 1e6) : 1.0;
    else
      damping_[r] = damping_[r] > 1e-3 ? 0.25 * damping_[r] : 0.0;
  }
}

}  // namespace abd
