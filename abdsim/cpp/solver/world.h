// The implicit ABD time stepper (ABD_NOTES §6). One time step minimises
//   Π(q) = ½ |q − q̃|²_M + c² [ Σ_b κ_b v̄_b Ψ_b(A_b) + Σ_terms E(q) ]
// over the stacked body state q (12 per body) by projected Newton, with
//   BDF1: c = h,    q̃ = q_t + h q̇_t + h² g_q,              q̇_{t+1} = (q_{t+1} − q_t)/h
//         (bodies that nothing pushes then move by −½ h² g_q: their exact parabola,
//         world_ballistic.cpp)
//   BDF2: c = 2h/3, q̃ = q̂ + c v̂ + c² g_q with q̂ = (4q_t − q_{t−1})/3, v̂ = (4q̇_t − q̇_{t−1})/3,
//         q̇_{t+1} = (q_{t+1} − q̂)/c   (the first step, or the first after set_state, is BDF1).
// Per-body flags: is_fixed (never moves), is_dynamic = 0 (quasi-static: q̃ = q_t + c² g_q),
// external_kinetic (no kinetic term), kinematic (scripted: held at its target during the
// solve, velocity from the target).
//
// Extra potentials (contact, joints, ...) plug in with add_term(); IPC contact is built in
// (enable_contact). Each Newton direction is first clipped to ccd_safety × min_terms
// max_step(q, Δq) when a term bounds it, then backtracked (Armijo) on Π. With no extra term
// bodies are independent and each body runs its own 12-dof Newton solve (the free-flight
// fast path, in parallel over bodies).
//
// With terms (world_coupled.cpp), terms that split by body (contact) say which bodies they
// couple: bodies that nothing comes near on their way to the prediction run that per-body
// solve and keep its free solution (they are done); the others form islands of coupled
// bodies that start where they are, each with its own CCD bound, line search and
// convergence, solved together (one linear system, one contact query per iteration) in
// lockstep. Islands merge as soon as a term links them.
//
// Kinematic bodies: held at their target (a hard constraint) when the move there is free of
// contact (CCD). A move that is not is *driven* for that step instead: the body becomes a
// free unknown with the energy s (½ (x − target)ᵀ M (x − target) + c² Ψ) (s =
// kinematic_drive_stiffness, M its mass matrix, Ψ its shape energy): the same body, s times
// heavier and stiffer, heading for the target. The barrier stops it short of anything it
// would cross and it pushes what it meets; the distance left to the target is reported as
// StepDiagnostics::kinematic_lag.
#pragma once
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "contact/damping/restitution.h"  // the restitution law, held by value
#include "mass/dyadic_mass.h"
#include "solver/block_system.h"
#include "solver/constrained_solve.h"
#include "solver/constraint.h"
#include "solver/diagnostics.h"
#include "solver/energy_term.h"
#include "solver/scene_data.h"
#include "solver/settings.h"
#include "solver/shape_energy_term.h"

namespace abd {

// Contact is one EnergyTerm among others to the Newton loop; only building it and reporting
// on it (world_contact.cpp) know its type.
class IpcContactTerm;
struct ContactSettings;

class World {
 public:
  // Throws std::invalid_argument for invalid scene data (non-finite state, dt <= 0,
  // singular mass matrix, unknown constitution, ...).
  explicit World(const SceneData& scene, const SolverSettings& settings = SolverSettings());

  // Adds a potential to Π (scaled by c² like the shape energy). Terms are evaluated in the
  // order they were added.
  void add_term(std::shared_ptr<EnergyTerm> term);
  void add_term(std::unique_ptr<EnergyTerm> term) { add_term(std::shared_ptr<EnergyTerm>(std::move(term))); }
  const std::vector<std::shared_ptr<EnergyTerm>>& terms() const { return terms_; }
  const ShapeEnergyTerm& shape_term() const { return shape_; }
  // Adds equality constraints (joints) that every step satisfies exactly (solver/
  // constraint.h); constrained bodies are solved in islands, never on the free fast path.
  void add_constraint(std::shared_ptr<Constraint> constraint);
  const std::vector<std::shared_ptr<Constraint>>& constraints() const { return constraints_; }

  // IPC contact between the bodies' surfaces (and the ground, if settings.ground): builds the
  // contact term from the scene, checks the current state (std::invalid_argument naming the
  // bodies if surfaces intersect or are closer than their thickness) and adds the term.
  // Once per world.
  IpcContactTerm& enable_contact(const ContactSettings& settings);
  // The contact term, or null.
  const std::shared_ptr<IpcContactTerm>& contact() const { return contact_; }
  // Smallest gap between contact primitives (and to the ground) at the current state, among
  // those closer than max_distance (<= 0: d̂); +inf if none, or without contact.
  double min_contact_distance(double max_distance = -1.0) const;

  // Advances one time step. Throws SolverError (state unchanged) when it cannot.
  const StepDiagnostics& step();

  int num_bodies() const { return n_; }
  double time() const { return time_; }
  // Time at the end of the next step (what kinematic schedules are evaluated at).
  double next_time() const {
    return time_base_ + static_cast<double>(step_count_ - step_base_ + 1) * scene_.dt;
  }
  long step_count() const { return step_count_; }
  const SceneData& scene() const { return scene_; }
  const SolverSettings& settings() const { return settings_; }
  const VecX& q() const { return q_; }
  const VecX& q_dot() const { return q_dot_; }
  Mat12 mass_matrix(int body) const { return mass_matrix_.at(check_body(body)); }
  // The last step's diagnostics (default values before the first step).
  const StepDiagnostics& diagnostics() const;
  // Diagnostics of the last `history_limit` steps, oldest first (0 keeps none).
  struct HistoryView {
    std::deque<StepDiagnostics>::const_iterator first, last;
    std::deque<StepDiagnostics>::const_iterator begin() const { return first; }
    std::deque<StepDiagnostics>::const_iterator end() const { return last; }
    std::size_t size() const { return static_cast<std::size_t>(last - first); }
  };
  HistoryView history() const;
  void set_history_limit(std::size_t limit);
  // Empties the history (diagnostics() still reads the last step).
  void clear_history();

  // Replaces the state (e.g. a reset or teleport); BDF2 restarts with a BDF1 step.
  void set_state(const VecX& q, const VecX& q_dot);
  void set_time(double t);
  // Makes `body` kinematic (if it is not yet) with its pose at the end of the next step.
  // The target stays until replaced: without a new one the body rests there.
  void set_kinematic_target(int body, const Vec12& q_target);
  // Hands a kinematic body back to the dynamics, with the velocity it had. With contact, it
  // must not be in contact with anything then (std::invalid_argument otherwise: it stays
  // kinematic). Contact ignores pairs of two kinematic or fixed bodies.
  void release_kinematic(int body);
  bool is_kinematic(int body) const { return kinematic_.at(check_body(body)) != 0; }

 private:
  int check_body(int body) const;
  std::string describe(int body) const;  // "body b (geometry g)" for messages
  void predict_body(int b, double c, bool bdf2, bool orthogonalise);
  void orthogonalise_prediction(int b);
  void finish_body(int b, double c);
  void step_per_body(double c, bool bdf2, StepDiagnostics& d);
  // world_restitution.cpp: the restitution law after a committed step (velocities only).
  void apply_restitution(StepDiagnostics& d);
  // Per-body Newton on ½|x − q̃|²_M + c² Ψ (no terms) from x; fills r, min alphas per
  // iteration into `alphas` (if given).
  struct BodyNewton {
    int status = 0;  // Status in world.cpp
    int iterations = 0;
    double step_translation = 0.0;  // last direction, velocity units
    double step_affine = 0.0;
    double residual = 0.0;
    double kinetic = 0.0;
    double shape = 0.0;
  };
  void newton_body(int b, double c2, Vec12& x, BodyNewton& r, std::vector<double>* alphas) const;
  // step(): one solve of scene_.dt from the state into x_ / q_dot_new_, and its commit.
  void solve_step(StepDiagnostics& d);
  void commit_step();
  // world_substeps.cpp: why the solved step (q_ -> x_) cannot be accepted ("" if it can):
  // its straight-line motion crosses contact, or a body inverts or flattens.
  std::string step_rejection() const;
  // After a commit: the smallest contact gap at the new state (min(gap within d̂, d̂)), so that
  // the next step's chord check can be skipped when no vertex moves far enough to close it.
  void remember_gap(const StepDiagnostics& d);
  // solve_step, then step_rejection; a SolverError's message is returned as the reason.
  std::string try_step(StepDiagnostics& d);
  // world_ballistic.cpp: after a BDF1 solve, the bodies nothing pushes onto their exact
  // parabola (x_ −= ½ h² g); and that shift undone (false if there was none).
  void shift_ballistic_bodies();
  bool undo_ballistic_shift();
  std::string applied_tolerances() const;  // "" or the per-body tolerances of the last solve
  bool path_crosses(const VecX& q0, const VecX& q1) const;
  // Redoes the step as 2, 4, 8, ... substeps; throws SolverError (state unchanged) if even
  // the finest fails, with `failure` (why the whole step failed) and the last reason.
  void advance_in_substeps(const std::string& failure, StepDiagnostics& d);
  // After the pieces: a BDF2 history one step h long from the last piece's (length `piece`).
  void restart_history_after_pieces(double piece);
  // world_coupled.cpp
  void solve_coupled(double c2, StepDiagnostics& d);
  void place_kinematic_bodies(StepDiagnostics& d);
  double step_bounds(const VecX& x, const VecX& dq, const std::vector<unsigned char>& mask,
                     std::vector<unsigned char>& near, std::vector<BodyLink>& links);
  // world_start.cpp: the Newton start, in its phases (start_iterate calls them in order).
  void start_iterate(bool split, double c2, StepDiagnostics& d);
  void head_for_warm_guesses(double c2);
  void join_movable_bodies();
  void check_start_moves();
  void solve_free_bodies(bool split, double c2, StepDiagnostics& d);
  bool place_start(bool split, StepDiagnostics& d);
  void recheck_warm_islands();
  void start_terms(bool all_clear);
  void freeze_free_islands();
  void lag_at_start();
  // world_friction_phases.cpp: the solve before a friction refresh converges its lagged
  // bodies to the settings' tolerances only (their tight ones saved); each iteration notes
  // whether a body's step also met its tight tolerances; after the refresh, the bodies it
  // changed and those that did not meet them iterate again (true when any does).
  void loosen_lagged_tolerances();
  void note_tight_convergence(int b, double st, double sa);
  bool retighten_after_refresh(bool changed);
  void balance_term_stiffness(double c2, const VecX& grad_bodies);
  // world_line_search.cpp: Armijo backtracking per island from x_ along dq_, each island
  // from its alpha_ (its step bound) down by halves; the accepted iterate is left in trial_
  // with its per-body Π in body_E_new_ and the rest of Π in rest_new. Returns -1, or the
  // root of an unconverged island for which no halving decreased Π (the solve fails).
  int armijo_search_islands(double c2, bool split, double rest,
                            std::vector<std::uint8_t>& inactive, double& rest_new,
                            StepDiagnostics& d);
  void sum_islands(bool split, double rest, const std::vector<std::uint8_t>& inactive,
                   int rest_root);
  // After a step (line search or whole): which islands' convergence stands, the smallest
  // alpha for the diagnostics, and each island's damping raised or relaxed.
  void judge_island_steps(const std::vector<std::uint8_t>& inactive, const VecX& island_ratio,
                          StepDiagnostics& d);
  // Π_b of one movable body without terms (kinetic or drive, plus c² shape); with g and H
  // (if non-null) its gradient and Hessian.
  double body_energy(int b, const Vec12& x, double c2, Vec12* g, Mat12* H) const;
  // Per-body energies at x (terms that split by body included) into E, the rest (terms that
  // do not split) returned; links found on the way appended.
  double body_energies(const VecX& x, double c2, VecX& E, std::vector<BodyLink>& links) const;
  double total_energy(const VecX& x, double c2, std::vector<double>* parts) const;
  void contact_diagnostics(StepDiagnostics& d) const;
  // world_constraints.cpp: the rows of every constraint at x, their use in the island start,
  // the projection of x_ onto them, and their violation.
  void constraint_rows(const VecX& x, std::vector<ConstraintRow>& rows) const;
  // The rows at x_ for a Newton solve: those of the last projection check when x_ has not
  // moved since (an articulation's start and every iterate after a projection), else new.
  void newton_constraint_rows(std::vector<ConstraintRow>& rows);
  void mark_jointed();
  void join_constrained_islands(std::vector<unsigned char>& near);
  // Where a body heads first: q̃ + c² a with a = (x − q̃)/c² of its last solve (its
  // contact, constraint and joint forces per unit mass, smooth from step to step while they
  // hold it), so that Newton starts within round-off of the solution's first-order part.
  // False when it has none.
  bool warm_guess(int b, double c2, Vec12& x) const;
  void remember_warm_start(double c2);
  // True when x_ moved (the start or iterate was off its constraints beyond round-off).
  // After a Newton step (`newton_step`) only the rows that are not linear are checked: the
  // step met the linear ones (the KKT solve) to round-off, far below the tolerance.
  bool project_constraints(bool newton_step = true);
  void constraint_diagnostics(StepDiagnostics& d) const;
  // islands (union-find over bodies; roots are the smallest index)
  int island(int b) {  // inline: the Newton loop asks for roots body by body
    while (parent_[b] != b) {
      parent_[b] = parent_[parent_[b]];
      b = parent_[b];
    }
    return b;
  }
  bool merge_islands(int a, int b);

  SceneData scene_;
  SolverSettings settings_;
  int n_ = 0;
  int threads_ = 1;
  std::vector<DyadicMass> dyadic_;
  std::vector<Mat12> mass_matrix_;  // dyadic_[b].matrix(), built once (a constant per body)
  // Half the smallest eigenvalue of mass_matrix_[b]: the negative curvature of the body's
  // shape energy that its kinetic term absorbs (ShapeEnergyTerm::add_body_derivatives).
  std::vector<double> mass_floor_;
  ShapeEnergyTerm shape_;
  std::vector<std::shared_ptr<EnergyTerm>> terms_;
  std::shared_ptr<IpcContactTerm> contact_;
  std::vector<std::shared_ptr<Constraint>> constraints_;
  std::vector<unsigned char> jointed_;  // movable bodies under a constraint this step
  KktFactorisation kkt_newton_, kkt_projection_;  // patterns kept from solve to solve
  bool nonlinear_constraints_ = false;
  VecX warm_accel_;                          // per body: (x − q̃)/c² of its last solve
  std::vector<unsigned char> warm_valid_;    // warm_accel_ holds a value for the body

  VecX q_, q_dot_;            // current state
  VecX q_prev_, q_dot_prev_;  // previous state (BDF2)
  contact::RestitutionLaw restitution_;
  VecX step_q_t_, step_q_dot_t_;  // the state at the start of the step (restitution law)
  bool has_history_ = false;
  // The state was given (construction, set_state), not reached by a step: terms may choose
  // what they lag for it afresh (StepContext::fresh_state).
  bool fresh_state_ = true;
  double time_ = 0.0;
  long step_count_ = 0;
  // time_ = time_base_ + (step_count_ - step_base_) * dt: no drift from summing dt.
  double time_base_ = 0.0;
  long step_base_ = 0;

  std::vector<std::uint8_t> fixed_, dynamic_, external_kinetic_, kinematic_;
  std::vector<std::uint8_t> constrained_;  // fixed or (hard) kinematic during this step
  std::vector<std::uint8_t> driven_;       // kinematic, driven by the stiff spring this step
  std::vector<unsigned char> movable_;     // unknowns of this step's solve
  std::vector<unsigned char> ballistic_;   // shifted onto the parabola (shift_ballistic_bodies)
  VecX kinematic_target_;

  // Per-step scratch.
  VecX q_hat_, q_tilde_;
  VecX x_pred_;  // where Newton heads first: q̃ with A re-orthogonalised (see predict_body)
  VecX x_, grad_, dq_, trial_, q_dot_new_;
  // Coupled solve: free per-body solutions, islands and their line-search state.
  VecX x_free_;
  std::vector<int> parent_;
  std::vector<std::uint8_t> frozen_, converged_, pending_, halved_;
  VecX tol_translation_, tol_affine_;  // this step's Newton tolerances per body
  // Before the friction refresh: the tolerances the lagged bodies (loose_) converge to after
  // it, and the bodies whose last step did not meet them yet (world_friction_phases.cpp).
  VecX tight_translation_, tight_affine_;
  std::vector<unsigned char> loose_, unfinished_;
  bool loose_phase_ = false;
  std::vector<double> radius_;          // largest distance of a vertex from the centre of mass
  std::vector<double> extent_;          // largest |x̄| of a vertex
  std::vector<int> free_iterations_;    // per-body Newton iterations of this step's free solves
  VecX damping_, alpha_, island_E_, island_E_new_, island_slope_, body_E_, body_E_new_, bound_;
  BlockSystem system_;
  std::vector<BodyBlock> blocks_;
  std::vector<HessianRow> hessian_rows_;
  std::vector<ConstraintRow> newton_rows_, projection_rows_;
  std::vector<ConstraintValue> constraint_values_;  // project_constraints' check
  std::vector<std::size_t> constraint_value_offsets_;  // where each constraint's values start
  VecX constraint_values_x_;                          // the x_ they were computed at
  VecX projection_rows_x_;           // the x_ projection_rows_ were computed at
  bool projection_rows_valid_ = false;
  VecX rhs_;
  // remember_gap: the gap, the state and the kinematic flags it was measured with.
  double gap_ = 0.0;
  VecX gap_q_;
  std::vector<std::uint8_t> gap_kinematic_;
  // Every step's diagnostics have one owner, steps_ (each step's moved in, never copied),
  // which keeps the last max(history_limit_, 1) steps: its back is the last step's
  // (diagnostics()), and history() shows its newest `reported_` entries (at most
  // history_limit_: the steps since the history was last cleared).
  std::deque<StepDiagnostics> steps_;
  std::size_t history_limit_ = 10000;
  std::size_t reported_ = 0;
  // Drops the oldest steps beyond what steps_ keeps; the last one dropped lends its lists'
  // storage (energies, line-search alphas) to the next step's diagnostics (fresh_step).
  void trim_steps();
  // A default StepDiagnostics whose (empty) lists reuse a dropped step's storage: a step
  // fills them without allocating once the history is full.
  StepDiagnostics fresh_step();
  std::vector<double> spare_alphas_;
  std::vector<std::pair<std::string, double>> spare_energies_;
  // solve_coupled's per-iteration scratch, kept from iteration to iteration and step to step
  // (no allocation once sized).
  std::vector<std::uint8_t> inactive_;
  std::vector<int> island_root_;
  std::vector<unsigned char> near_;
  std::vector<BodyLink> links_;
  std::vector<double> term_parameters_;
  std::vector<double> energy_parts_;
  VecX island_st_, island_sa_, island_ratio_, slope_exact_, dq_newton_;
  // place_kinematic_bodies' and start_iterate's per-body flags and links (world_start.cpp),
  // kept from step to step.
  struct StartScratch {
    VecX dq;  // the kinematic bodies' moves
    std::vector<unsigned char> moving, near, warm, warm_island, stays, solved, strayed;
    std::vector<unsigned char> engaged, free_island;
    std::vector<BodyLink> links;
    std::vector<BodyLink> constraint_links;  // join_constrained_islands'
    // The first check of the start move: its bound for the terms that do not split, and
    // the largest reach of a term.
    double global = 1.0, reach = 0.0;
    // A move whose step bounds were computed (step_bounds with the movable mask): the
    // checks of this start, so that the last one is not run again for the same move.
    struct CheckedMove {
      VecX from, dq, bound;
      double global;
    };
    std::vector<CheckedMove> checked;
  } start_;
};

}  // namespace abd
