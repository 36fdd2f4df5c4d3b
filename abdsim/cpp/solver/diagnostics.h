// What one time step did, and the exception a failed step throws.
#pragma once
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace abd {

// A step that could not be completed (Newton or line search failure, a singular system,
// non-finite values). The world is left at the state it had before the step.
class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct StepDiagnostics {
  long step = 0;       // index of the step (0 for the first one taken)
  double time = 0.0;   // simulated time at the end of the step
  // Newton iterations: the global count, or with the per-body fast path the largest count
  // over bodies; `total_body_iterations` sums them over bodies (= n_bodies * iterations on
  // the global path).
  int newton_iterations = 0;
  long total_body_iterations = 0;
  bool converged = false;
  // Last Newton direction in velocity units: max_k |Δp_k| / h (m/s), max |ΔA_kl| / h (1/s).
  double step_translation = 0.0;
  double step_affine = 0.0;
  // max |∇Π| (infinity norm) at the start of the last Newton iteration.
  double residual = 0.0;
  // Accepted line-search step per Newton iteration (fast path: the smallest over bodies).
  std::vector<double> line_search_alphas;
  // Smallest max_step bound a term returned (1 when nothing limited the step).
  double min_term_max_step = 1.0;
  // Energies at the end of the step: "kinetic" (½|q-q̃|²_M), "shape" and each added term
  // (potentials, not scaled by h²), then "total" = Π.
  std::vector<std::pair<std::string, double>> energies;
  std::string linear_solver;  // "block_diagonal", "direct" or "pcg"
  long pcg_iterations = 0;    // summed over Newton iterations
  double wall_time = 0.0;     // seconds
};

}  // namespace abd
