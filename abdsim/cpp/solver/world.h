// The implicit ABD time stepper (ABD_NOTES §6). One time step minimises
//   Π(q) = ½ |q − q̃|²_M + c² [ Σ_b κ_b v̄_b Ψ_b(A_b) + Σ_terms E(q) ]
// over the stacked body state q (12 per body) by projected Newton, with
//   BDF1: c = h,    q̃ = q_t + h q̇_t + h² g_q,              q̇_{t+1} = (q_{t+1} − q_t)/h
//   BDF2: c = 2h/3, q̃ = q̂ + c v̂ + c² g_q with q̂ = (4q_t − q_{t−1})/3, v̂ = (4q̇_t − q̇_{t−1})/3,
//         q̇_{t+1} = (q_{t+1} − q̂)/c   (the first step, or the first after set_state, is BDF1).
// Per-body flags: is_fixed (never moves), is_dynamic = 0 (quasi-static: q̃ = q_t + c² g_q),
// external_kinetic (no kinetic term), kinematic (scripted: held at its target during the
// solve, velocity from the target).
//
// Extra potentials (contact, joints, ...) plug in with add_term(). Each Newton direction is
// first clipped to ccd_safety × min_terms max_step(q, Δq) when a term bounds it, then
// backtracked (Armijo) on Π. With no extra term bodies are independent and each body runs
// its own 12-dof Newton solve (the free-flight fast path, OpenMP over bodies).
#pragma once
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "mass/dyadic_mass.h"
#include "solver/block_system.h"
#include "solver/diagnostics.h"
#include "solver/energy_term.h"
#include "solver/scene_data.h"
#include "solver/settings.h"
#include "solver/shape_energy_term.h"

namespace abd {

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
  Mat12 mass_matrix(int body) const { return dyadic_.at(check_body(body)).matrix(); }
  const StepDiagnostics& diagnostics() const { return diag_; }
  // Diagnostics of the last `history_limit` steps, oldest first (0 keeps none).
  const std::deque<StepDiagnostics>& history() const { return history_; }
  void set_history_limit(std::size_t limit);
  void clear_history() { history_.clear(); }

  // Replaces the state (e.g. a reset or teleport); BDF2 restarts with a BDF1 step.
  void set_state(const VecX& q, const VecX& q_dot);
  void set_time(double t);
  // Makes `body` kinematic (if it is not yet) with its pose at the end of the next step.
  // The target stays until replaced: without a new one the body rests there.
  void set_kinematic_target(int body, const Vec12& q_target);
  // Hands a kinematic body back to the dynamics, with the velocity it had.
  void release_kinematic(int body);
  bool is_kinematic(int body) const { return kinematic_.at(check_body(body)) != 0; }

 private:
  int check_body(int body) const;
  std::string describe(int body) const;  // "body b (geometry g)" for messages
  void predict_body(int b, double c, bool bdf2);
  void finish_body(int b, double c);
  void step_per_body(double c, bool bdf2, StepDiagnostics& d);
  void solve_global(double c2, StepDiagnostics& d);
  void initial_guess(double c2, StepDiagnostics& d);
  double total_energy(const VecX& x, double c2, std::vector<double>* parts) const;

  SceneData scene_;
  SolverSettings settings_;
  int n_ = 0;
  int threads_ = 1;
  std::vector<DyadicMass> dyadic_;
  ShapeEnergyTerm shape_;
  std::vector<std::shared_ptr<EnergyTerm>> terms_;

  VecX q_, q_dot_;            // current state
  VecX q_prev_, q_dot_prev_;  // previous state (BDF2)
  bool has_history_ = false;
  double time_ = 0.0;
  long step_count_ = 0;
  // time_ = time_base_ + (step_count_ - step_base_) * dt: no drift from summing dt.
  double time_base_ = 0.0;
  long step_base_ = 0;

  std::vector<std::uint8_t> fixed_, dynamic_, external_kinetic_, kinematic_;
  std::vector<std::uint8_t> constrained_;  // fixed or kinematic during this step
  VecX kinematic_target_;

  // Per-step scratch.
  VecX q_hat_, q_tilde_;
  VecX x_pred_;  // where Newton heads first: q̃ with A re-orthogonalised (see predict_body)
  VecX x_, grad_, dq_, trial_, q_dot_new_;
  BlockSystem system_;
  std::vector<BodyBlock> blocks_;
  StepDiagnostics diag_;
  std::deque<StepDiagnostics> history_;
  std::size_t history_limit_ = 10000;
};

}  // namespace abd
