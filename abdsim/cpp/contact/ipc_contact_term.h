// IPC contact (barrier + lagged friction + lagged normal damping) between affine bodies and
// with an analytic ground, as one EnergyTerm (solver/energy_term.h). Value, gradient and
// Hessian are the potential
//     Σ_active κ m_k b(d_k²; d̂, ξ_k)  +  Σ_lagged μ_k λ_k f0(|u_k|; ε_v h)
//       + Σ_lagged C_k / (2c) (n_kᵀ r_k)²     (damping/normal_damping.h)
// (the solver scales by h², c² for BDF2). Vertex-space Hessians are PSD-projected per stencil (unless
// ContactSettings::project_hessian is false) and mapped to 12×12 body blocks J_iᵀ H J_j. Fixed bodies take part (they only do not move); pairs of two
// fixed (or scripted, see set_scripted) bodies are ignored, they can neither move apart nor be
// helped.
//
// Call order the solver should follow each step:
//   begin_step(ctx)            lag friction at q_t (normal forces, bases, closest points);
//                              ctx.potential_scale (c²) sets the scale of adaptive κ
//   [initialize_kappa(q, g)]   adaptive κ only: balance against the rest of ∇Π (IPC)
//   repeat: update(q) → gradient/Hessian at q → max_step(q, dq) → line search on value(q')
// value/add_gradient/add_hessian are exact at any q: at the q of the last update() they reuse
// its active set, elsewhere they build one on the fly. With adaptive κ, update() may double κ
// (IPC: the closest gap is below 1e-9 × bbox diagonal and shrinking), so re-evaluate the
// energy at the accepted iterate after update(). max_step returns 0 when some pair already
// starts within its thickness (an invalid state; check_initial says which).
//
// Not thread-safe for concurrent calls on one object: the broad phase's BVHs are a cache that
// const methods refit.
#pragma once
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "common/stopwatch.h"
#include "contact/active_set.h"
#include "contact/barrier/adaptive_stiffness.h"
#include "contact/body_mapping.h"
#include "contact/broad_phase/broad_phase.h"
#include "contact/contact_force.h"
#include "contact/contact_mesh.h"
#include "contact/contact_table.h"
#include "contact/damping/normal_damping.h"
#include "contact/friction_set.h"
#include "contact/swept_reach.h"
#include "contact/verlet_candidates.h"
#include "solver/energy_term.h"
#include "solver/scene_data.h"

namespace abd {

using contact::ContactRule;
using contact::ContactRuleFn;

struct ContactSettings {
  double d_hat = 1e-3;   // barrier activation distance (m), beyond the thickness
  double kappa = 0.0;    // contact stiffness κ_c; <= 0: adaptive (IPC), starting at κ_min
  double mu = 0.5;       // default friction coefficient (0 disables friction)
  double eps_v = 1e-3;   // friction smoothing speed (m/s), used as ε_v h
  double damping = 0.0;  // default normal damping ratio ζ of every pair (0: none)
  // Default coefficient of restitution e in [0, 1] of every pair (< 0: none, the integrator's
  // own), and the approach speed (m/s) below which a pair's impact is left to the integrator
  // (damping/restitution.h).
  double restitution = -1.0;
  double restitution_threshold = 0.2;
  bool ground = false;   // the half-space z >= ground_height is a fixed obstacle
  double ground_height = 0.0;
  int ground_contact_element = 0;
  std::vector<int> body_contact_element;  // one contact element id per body; empty: all 0
  ContactRuleFn contact_table;  // (element a, element b) -> {collide?, μ, ζ}; empty: all, mu

  double ccd_target = 0.1;  // CCD keeps at least this fraction of each pair's gap (safety)
  bool project_hessian = true;  // PSD-project each barrier stencil (false: exact, for tests)
};

struct ContactCounts {
  int point_triangle = 0;
  int edge_edge = 0;
  int point_ground = 0;
  int friction = 0;
  int damping = 0;  // lagged normal dampers
};

class IpcContactTerm : public EnergyTerm {
 public:
  explicit IpcContactTerm(const SceneData& scene, const ContactSettings& settings = {});
  IpcContactTerm(const IpcContactTerm&) = delete;
  IpcContactTerm& operator=(const IpcContactTerm&) = delete;

  std::string name() const override { return "ipc_contact"; }
  void begin_step(const StepContext& ctx) override;
  // Friction lagged again at the converged q (normal forces, bases, closest points), still
  // sliding from the step's reference point: IPC's friction iterations.
  bool refresh_lagged(const VecX& q) override;
  // Contact began or ended over the step: some pair is inside d̂ at its end and none was at
  // its start, or the other way round.
  bool broke_smoothness() const override {
    return compressed_at_start_ != !active_.stencils.empty();
  }
  void update(const VecX& q) override;
  double value(const VecX& q) const override;
  void add_gradient(const VecX& q, double scale, VecX& gradient) const override;
  void add_hessian(const VecX& q, double scale, std::vector<BodyBlock>& blocks) const override;
  void add_gradient_and_hessian(const VecX& q, double scale, VecX& gradient,
                                std::vector<BodyBlock>& blocks) const override;
  double max_step(const VecX& q, const VecX& dq) const override;

  // Splitting by body (solver/energy_term.h): every stencil involves one or two bodies (the
  // ground is none), so the solver can run independent groups of bodies separately.
  bool splits_by_body() const override { return true; }
  void add_body_values(const VecX& q, const std::vector<unsigned char>& movable, VecX& per_body,
                       std::vector<BodyLink>& links) const override;
  void body_links(const std::vector<unsigned char>& movable,
                  std::vector<BodyLink>& links) const override;
  // Candidates are those within d̂ (+ thickness) along the path, so `near` and `links` cover
  // every pair whose barrier may become active; bounds are the ACCD times of impact.
  void body_max_steps(const VecX& q, const VecX& dq, const std::vector<unsigned char>& movable,
                      VecX& bound, std::vector<unsigned char>& near,
                      std::vector<BodyLink>& links) const override;

  // The most candidate pairs one broad-phase query may collect (memory: ~90 bytes each
  // with its stencil and time of impact). Default: 2 per primitive, at least 2^20. A swept
  // query over this shortens the move (body_max_steps); a query at one configuration over
  // it throws SolverError.
  size_t max_candidates() const { return max_candidates_; }
  void set_max_candidates(size_t n);
  // Candidates kept by the last body_max_steps, and the fraction of its dq each body's
  // checked move took (1: all of it; < 1: shortened to keep the sweep within
  // max_candidates). Empty before any.
  size_t swept_candidate_count() const { return swept_.valid ? swept_.candidates.size() : 0; }
  const std::vector<double>& swept_scale() const { return swept_.scale; }

  // Smallest gap d − ξ between primitives (and to the ground) that is below max_distance
  // (<= 0: d̂); +inf when nothing is that close.
  double min_distance(const VecX& q, double max_distance = -1.0) const;
  // True when the straight line q → q + dq brings a pair into contact. Each pair's CCD
  // (which stops at ccd_target of its gap) restarts where it stopped, at most `restarts`
  // times in all: a pair still short of the end then closed its gap by > 10^restarts and
  // touches or crosses, and so does one that restarts from a gap at or below `touching`,
  // whatever its CCD answers from there (at round-off it finds no impact, and may pass
  // through the surface it was closing on). Throws std::invalid_argument for restarts < 1
  // or a touching gap that is negative or not finite.
  bool line_crosses(const VecX& q, const VecX& dq, int restarts, double touching) const;
  // Throws std::invalid_argument naming the bodies if q has intersecting surfaces, primitives
  // closer than their thickness, or vertices at/below the ground (plus thickness).
  void check_initial(const VecX& q) const;

  // Coefficient of restitution of bodies a and b (b = −1: the ground); < 0: none.
  double restitution(int a, int b) const {
    return b < 0 ? table_.ground(a).restitution : table_.bodies(a, b).restitution;
  }
  bool has_restitution() const { return table_.any_restitution(); }

  double barrier_value(const VecX& q) const;
  double friction_value(const VecX& q) const;
  double damping_value(const VecX& q) const;

  // Scripted bodies (kinematic: the solver moves them along a prescribed path) collide with
  // dynamic bodies only: pairs of two scripted or fixed bodies, and scripted bodies with the
  // ground, are ignored (nothing could resolve them), here and in check_initial.
  void set_scripted(int body, bool scripted);
  bool scripted(int body) const { return scripted_.at(body) != 0; }

  // Threads for the heavy per-stencil loops (the solver's worker pool); 0: all.
  void set_threads(int threads);

  double kappa() const { return kappa_; }
  // Wall-clock seconds spent in broad-phase queries since construction (for the profile).
  double broad_phase_seconds() const { return broad_phase_seconds_; }
  void set_kappa(double kappa);
  bool adaptive_kappa() const { return settings_.kappa <= 0.0; }
  // Adaptive κ only (otherwise returns kappa()): IPC's gradient balance against grad_rest,
  // the gradient of the rest of Π at q, clamped to [κ_min, κ_max].
  double initialize_kappa(const VecX& q, const VecX& grad_rest);
  contact::BarrierStiffness stiffness_bounds() const { return {kappa_, kappa_min_, kappa_max_}; }

  // update(q) for a caller that knows no pair is within d̂ at q (e.g. from body_max_steps
  // along a move that ends at q): the empty active set, without a broad-phase query.
  void set_no_active_pairs(const VecX& q);
  // Sets flags[b] = 1 for every body in a lagged friction or damping pair of this step.
  void mark_friction_bodies(std::vector<unsigned char>& flags) const;
  // Sets flags[b] = 1 for every body in an active pair of the last update() (within d̂).
  void mark_active_bodies(std::vector<unsigned char>& flags) const override;
  // Both of the above: the bodies a barrier, friction or damping element may push.
  void mark_forced_bodies(std::vector<unsigned char>& flags) const override {
    mark_active_bodies(flags);
    mark_friction_bodies(flags);
  }

  // The solver's generic hooks (solver/energy_term.h; ipc_contact_hooks.cpp): friction's
  // tolerances (0.1 ε_v at the surface), its lagged bodies, adaptive κ balanced at the start
  // iterate and doubled by update(), d̂ as the reach, no query after a checked clear move.
  void limit_tolerances(VecX& tol_translation, VecX& tol_affine,
                        const std::vector<double>& radius) const override;
  void mark_lagged_bodies(std::vector<unsigned char>& flags) const override;
  bool balances_stiffness() const override;
  void balance_stiffness(const VecX& q, const VecX& grad_rest) override;
  double energy_parameter() const override { return kappa_; }
  // Friction's Hessian majorises it (friction/friction_potential.h) while on.
  void set_majorizing_model(bool on) override { majorize_friction_ = on; }
  double reach() const override { return settings_.d_hat; }
  void update_clear(const VecX& q) override { set_no_active_pairs(q); }

  // Forces at q of the active pairs (barrier) and of this step's lagged friction pairs, one
  // record per pair with a non-zero force (ipc_contact_forces.cpp). At the state the solver
  // converged to, these are the forces its step applied. Throws std::invalid_argument when q
  // is infeasible (surfaces within their thickness).
  std::vector<contact::ContactForce> contact_forces(const VecX& q) const;
  // Net contact force and torque on each body, rows [f, τ] (n_bodies × 6), the torque about
  // centers[b] (world); the same forces as contact_forces, summed per vertex.
  contact::WrenchMatrix contact_wrenches(const VecX& q, const std::vector<Vec3>& centers) const;

  // Diagnostics about the last update() and begin_step().
  ContactCounts counts() const;
  const std::vector<contact::ContactStencil>& active_stencils() const { return active_.stencils; }
  const contact::ContactMesh& mesh() const { return mesh_; }
  const ContactSettings& settings() const { return settings_; }
  double bbox_diagonal() const { return bbox_diagonal_; }
  // The length IPC's κ_min is measured against (its "bbox diagonal": κ_min makes the
  // barrier's curvature at a gap of 1e-8 of it match the mass). IPC takes the scene's size;
  // here it is 1e3 d̂, so that the reference gap is 1e-5 d̂ whatever the scene's size: with
  // the scene's size a 10 cm box rested half-way into d̂ and tilted by milliradians under
  // friction (rocking back when it stopped), and small parts got a far softer barrier.
  double stiffness_length() const { return 1e3 * settings_.d_hat; }

 private:
  contact::BarrierParams barrier_params(double kappa) const;
  contact::ActiveSet build_active_set(const VecX& q, double reach) const;
  const contact::ActiveSet& active_set_at(const VecX& q, contact::ActiveSet& scratch) const;
  void add_barrier_gradient(const contact::ActiveSet& set, double kappa, double scale,
                            VecX& gradient) const;
  bool bodies_may_collide(int a, int b) const;
  void add_derivatives(const VecX& q, double scale, VecX* gradient,
                       std::vector<BodyBlock>& blocks) const;
  void lag_dissipation();  // friction_ and damping_ from active_ and the reference point
  std::vector<double> inverse_masses() const;
  // The candidates of a query at one configuration; SolverError beyond max_candidates_.
  contact::Candidates bounded_query(const std::vector<Vec3>& x,
                                    const contact::BroadPhaseQuery& query) const;
  // A swept query of the move q → q + dq within max_candidates_ (ipc_contact_sweep.cpp):
  // bodies that move far get a shortened move q_b + scale_b dq_b (scale_b in (0, 1]) until
  // the query fits; each candidate's time of impact is a fraction of the pair's common
  // shortened move (the smaller scale of its two bodies). SolverError when even tiny moves
  // overflow.
  struct Sweep {
    std::vector<contact::ContactStencil> stencils;
    std::vector<double> toi;         // per stencil: step bound as a fraction of the full dq
    std::vector<double> scale;       // per body
    contact::Candidates candidates;
    // per stencil, only for a sweep with margin > 0: its gap bound along the path
    std::vector<contact::PathReach> reach;
    // The vertices at q the sweep started from (a cache of the term's, valid until its next
    // sweep or update): callers that restart along the same line need not transform them again.
    const std::vector<Vec3>* x0 = nullptr;
  };
  Sweep bounded_sweep(const VecX& q, const VecX& dq, double margin) const;
  // True when every body of q lies on its segment of the last body_max_steps move:
  // q_b = q0_b + t_b dq_b with t_b in [0, 1] (to rounding); t (one per body) gets the t_b.
  bool on_swept_path(const VecX& q, std::vector<double>& t) const;
  // The world vertices at q: those of the active set, the last set built or the last
  // sweep's end when one describes q (the solver asks at one iterate for energies, gradients
  // and step bounds: a 5,000-vertex robot spent a third of its step recomputing them), else
  // computed into `scratch`.
  const std::vector<Vec3>& vertices_at(const VecX& q, std::vector<Vec3>& scratch) const;

  // The two bodies of a stencil's vertices (second -1 for the ground).
  std::array<int, 2> stencil_bodies(const std::array<int, 4>& vertices, int nv) const;

  ContactSettings settings_;
  contact::ContactMesh mesh_;
  contact::ContactTable table_;
  mutable contact::BroadPhase broad_phase_;  // a cache of refit BVHs (see above)
  // broad_phase_'s answers reused while vertices stay within 2 d̂ of where the list was
  // built (verlet_candidates.h: the same candidates, exactly); reset by set_scripted.
  mutable contact::VerletCandidates verlet_;
  mutable double broad_phase_seconds_ = 0.0;  // see broad_phase_seconds()
  // The candidates of the last body_max_steps move q0 → q0 + dq, within d̂ anywhere on it:
  // a superset of the pairs within d̂ at any point where each body is somewhere on its own
  // segment (each primitive's box there lies inside its swept box), so the line search's
  // active sets take them instead of querying the broad phase at every trial.
  struct SweptCandidates {
    VecX q0, dq;  // dq: each body's checked (possibly shortened) move
    contact::Candidates candidates;
    std::vector<double> scale;  // per body: its share of the full dq (bounded_sweep)
    // per candidate: the bound on its gap along the path (swept_reach.h), by which a trial
    // selects its active set from the few candidates that can be within d̂ there
    std::vector<contact::PathReach> reach;
    bool valid = false;
  };
  mutable SweptCandidates swept_;
  // Scratch of build_active_set: the per-body path times and reachable candidates of a trial.
  mutable std::vector<double> trial_times_;
  mutable contact::Candidates trial_candidates_;
  // bounded_sweep's vertex buffers, kept to spare a large allocation per sweep (the term is
  // never evaluated from two threads at once).
  mutable std::vector<Vec3> sweep_start_, sweep_end_;
  // add_derivatives' per-body-pair sums, kept for their storage (cleared at each call).
  mutable contact::BodyBlockAccumulator block_accumulator_;
  // The q of sweep_end_ (the end q + dq of the last sweep): the line search's first full step
  // is that very point, whose vertices vertices_at then takes from there.
  mutable VecX sweep_end_q_;
  size_t max_candidates_ = size_t(1) << 20;  // see max_candidates()
  std::vector<char> scripted_;  // per body, see set_scripted
  int threads_ = 1;
  contact::ActiveSet active_;
  // The last set built for another q (line-search trials): update() at that q reuses it.
  mutable contact::ActiveSet last_built_;
  double potential_scale_ = 0.0;  // c² of the current step (h², or (2h/3)² for BDF2)
  // c: the time scale that turns displacements from the reference point into velocities.
  double step_scale() const { return potential_scale_ > 0.0 ? std::sqrt(potential_scale_) : dt_; }
  std::vector<contact::FrictionStencil> friction_;
  double friction_eps_ = 0.0;  // ε_v c
  bool majorize_friction_ = false;  // see set_majorizing_model
  std::vector<Vec3> friction_ref_;  // vertex positions at the step's reference point
  std::vector<contact::DampingStencil> damping_;
  double dt_ = 0.01;
  double bbox_diagonal_ = 1.0;
  double average_mass_ = 1.0;
  double kappa_ = 0.0, kappa_min_ = 0.0, kappa_max_ = 0.0;
  double prev_min_gap_ = -1.0;  // for the adaptive update; < 0: none yet
  // Some pair was inside d̂ at this step's start: κ stays as it is (see begin_step).
  bool compressed_at_start_ = false;
  // The steps start from a state no step ended in (the first, or after set_state) with
  // pairs inside d̂: initialize_kappa chooses κ for it once (the balance, see there).
  bool fresh_compressed_ = false;
};

}  // namespace abd
