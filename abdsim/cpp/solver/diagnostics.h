// What one time step did, and the exception a failed step throws.
#pragma once
#include <limits>
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
  // Newton iterations: the largest count over bodies (per-body fast path), or the count of
  // the coupled iterations (with terms; at least that of any body that kept its free
  // per-body solution); `total_body_iterations` sums the iterations each body took part in.
  int newton_iterations = 0;
  long total_body_iterations = 0;
  bool converged = false;
  // Order of the step's integrator: 1 (BDF1, also BDF2's first step, its first after
  // set_state and its first after contact began or ended), or 2.
  int integrator_order = 1;
  // Impulses the restitution law applied after the step (contact/damping/restitution.h).
  int restitution_impulses = 0;
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
  // Coupled solve: bodies that took part in the Newton iterations (the others kept their
  // free per-body solution), and the islands they formed.
  int coupled_bodies = 0;
  int islands = 0;
  // Contact at the end of the step (zero / +inf / 0 without contact): active primitive
  // pairs by kind, lagged friction pairs, the smallest gap d − ξ among the active pairs
  // (+inf when nothing is within d̂), and the barrier stiffness κ (the term's κ = IPC's
  // κ / h²). The CCD bound is min_term_max_step.
  int contact_point_triangle = 0;
  int contact_edge_edge = 0;
  int contact_point_ground = 0;
  int contact_friction = 0;
  double min_contact_distance = std::numeric_limits<double>::infinity();
  double contact_kappa = 0.0;
  // Kinematic bodies driven this step because their move would have crossed contact (see
  // World), and the largest distance a vertex of one of them was left from its target (m).
  int driven_bodies = 0;
  double kinematic_lag = 0.0;
  int kinematic_lag_body = -1;
  // Substeps the step was split into (1: solved whole). A step whose straight-line motion
  // would cross contact, invert or flatten a body, or that Newton could not solve, is redone
  // as 2, 4, 8, ... substeps; the counts above then sum (iterations, including those of the
  // failed whole step, failed pieces and refinement rounds redone finer: all the work the
  // step cost) or take the extreme (CCD bound) over them, the rest is the last substep's.
  int substeps = 1;
  // Why the whole step was not accepted (empty when substeps == 1): Newton's failure, the
  // straight line crossing contact, or a body inverting.
  std::string substep_reason;
  // The share of the counts and of wall_time spent on work the step threw away (0 when
  // substeps == 1): the rejected whole step, failed pieces and refinement rounds redone
  // finer. What a step redone in pieces costs beyond its kept pieces (issue 12: ~40% of the
  // iterations of the 100-box heap's substepped steps).
  int discarded_newton_iterations = 0;
  double discarded_time = 0.0;  // seconds
  // Equality constraints (joints) at the end of the step: the largest anchor separation (m)
  // and axis/frame misalignment (rad); zero without constraints.
  double joint_violation = 0.0;
  double joint_violation_angle = 0.0;
  std::string linear_solver;  // "block_diagonal", "direct", "pcg" or "none"
  long pcg_iterations = 0;    // summed over Newton iterations
  double wall_time = 0.0;     // seconds
  // Profile of the coupled solve (always on; seconds, summed over the step's Newton
  // iterations): assembling gradient and Hessian (bodies and terms), the linear solve
  // (sparse symbolic analysis + numeric factorisation + solve, or PCG), the step bounds
  // (CCD, with their broad phase), the line search's energy evaluations, the terms'
  // update() after each accepted iterate (the contact set), and the contact broad phase
  // within all of these.
  double time_assembly = 0.0;
  double time_linear_solve = 0.0;
  double time_ccd = 0.0;
  double time_line_search = 0.0;
  double time_contact_update = 0.0;
  double time_broad_phase = 0.0;
  // Line searches whose first trial was cut by the step bound (CCD), Armijo halvings
  // summed over all line searches and islands, and sparse symbolic analyses (the sparsity
  // pattern of the coupled system changed; otherwise the last analysis is reused).
  int line_search_ccd_cuts = 0;
  int line_search_halvings = 0;
  int symbolic_analyses = 0;
};

}  // namespace abd
