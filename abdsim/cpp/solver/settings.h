// Settings of the implicit time stepper (ABD_NOTES §6). Defaults are the documented ones;
// the Python Scene fills this struct from its settings dataclass.
#pragma once

namespace abd {

enum class Integrator : int {
  kBDF1 = 1,  // implicit Euler: robust, dissipative
  kBDF2 = 2,  // second order, much less numerical damping (first step is BDF1)
};

enum class LinearSolverKind : int {
  kAuto = 0,    // block-diagonal when nothing couples bodies, else direct below
                // `direct_max_dofs`, PCG above
  kDirect = 1,  // Eigen SimplicialLDLT on the assembled sparse matrix
  kPCG = 2,     // conjugate gradients with a 12x12 block-Jacobi preconditioner
};

struct SolverSettings {
  Integrator integrator = Integrator::kBDF1;

  // Newton stops when the largest per-body step, in velocity units, is below these:
  // every |Δp_k| <= tol_translation * h and every |ΔA_kl| <= tol_affine * h. The converged
  // step is still applied, so the error left is of second order in these numbers.
  double tol_translation = 0.01;  // m/s
  double tol_affine = 0.1;        // 1/s
  // Contact steps where bodies settle on edges and corners can take tens of iterations.
  int max_newton_iterations = 200;
  // Friction iterations (IPC): after Newton converges, terms re-evaluate what they lagged
  // at the step start (friction's normal forces and tangent bases) at the solution, and
  // Newton goes on; this many times per step. 0: lagged once, at the step start (a body
  // that starts a step compressed in the barrier then gets a transient normal force as
  // its friction bound).
  int friction_iterations = 1;

  // Backtracking (Armijo) line search on Π. The first trial step is clipped to
  // ccd_safety * min_terms max_step when a term limits it (IPC's CCD filter).
  double armijo_c = 1e-4;
  int max_line_search_iterations = 40;  // halvings
  double ccd_safety = 0.8;

  // Linear solve. kAuto: bodies not coupled by any Hessian block are solved per body
  // (12x12 Cholesky); coupled systems use the sparse direct solver up to
  // `direct_max_dofs` unknowns (1,000 bodies) and PCG above.
  LinearSolverKind linear_solver = LinearSolverKind::kAuto;
  int direct_max_dofs = 12000;
  double pcg_tolerance = 1e-8;  // relative residual |r| / |b|
  int pcg_max_iterations = 2000;

  // Kinematic bodies whose move would cross contact are driven towards their target for that
  // step by s (½ (x − target)ᵀ M (x − target) + c² Ψ) (world.h): the body s times heavier
  // and stiffer heading for the target (with h = 0.01 s and s = 1e4 a 1 kg link is a
  // 1e8 N/m spring on its centre).
  double kinematic_drive_stiffness = 1e4;

  // Project the shape energy's Hessian to PSD (always wanted; off only for experiments).
  bool project_psd = true;
  // Evaluate Π and its parts at each step's end into StepDiagnostics::energies (MuJoCo's
  // mjENBL_ENERGY; on by default here). Off: energies is empty and the step skips that pass
  // over bodies and terms; nothing else changes (the energies are only reported). They cannot
  // be evaluated later from the history: a term's value depends on that step's state of
  // the term (its controls, predictions, stiffness), which Python terms keep to themselves.
  bool energies = true;
  // Worker threads for the per-body and per-stencil loops; 0 = all hardware threads. Results
  // do not depend on it.
  int num_threads = 0;
};

}  // namespace abd
