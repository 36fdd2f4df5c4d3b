// The interface every potential in the incremental potential implements (shape energy,
// joints, IPC barrier, friction, ...). The Newton solver owns q and knows nothing about what
// a term computes; a term only sees the stacked body state q (12 * n_bodies) and
// returns values, gradients and PSD Hessian blocks in 12x12 body-block form.
//
// Conventions:
//  * value/gradient/hessian are the *potential* (not multiplied by h^2): the solver scales.
//  * add_gradient / add_hessian ADD `scale *` their contribution.
//  * Hessian blocks must be PSD as a whole (project per element before mapping J^T H J).
//  * Blocks are those of the full matrix: a coupling between bodies i != j is given as both
//    (i, j) and (j, i) = (i, j)^T (the solver checks this); blocks with the same (row, col)
//    are summed. Blocks touching fixed or kinematic bodies may be returned: the solver keeps
//    only their part on free bodies.
//  * Results must be deterministic: no accumulation order that depends on thread timing.
//
// Plugging a term in (see solver/world.h): C++ `world.add_term(std::make_unique<T>(...))`;
// from Python, bind T as py::class_<T, EnergyTerm, std::shared_ptr<T>> and call
// `world.add_term(term)`. The solver calls begin_step once per step, then per Newton
// iteration add_gradient/add_hessian, max_step(q, dq) to bound the step (the line search
// starts at ccd_safety * bound when bound < 1), value() at every line-search trial, and
// update(q) after every accepted iterate.
#pragma once
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "common/types.h"

namespace abd {

// One 12x12 block of the global Hessian, for body rows `row` and body columns `col`.
struct BodyBlock {
  int row;
  int col;
  Mat12 H;
};

// A rank-one Hessian contribution k (g_a ⊕ g_b)(g_a ⊕ g_b)ᵀ on bodies a and b (b = −1: on a
// alone), k > 0: the Gauss–Newton Hessian of a potential of one scalar coordinate s(q) with
// ∇s = (g_a, g_b). Handed as a row instead of three or four dense 12x12 blocks, it lets the
// linear solve treat it like a constraint row with compliance 1/k (the KKT solves of
// solver/constrained_solve.h), which costs a fraction of a dense coupling block.
struct HessianRow {
  int a;
  int b;
  Vec12 ga;
  Vec12 gb;
  double k;
};

// Two bodies an energy term couples (see EnergyTerm::splits_by_body).
struct BodyLink {
  int a;
  int b;
};

struct StepContext {
  double dt;
  const VecX& q_t;      // state at the start of the step
  const VecX& q_dot_t;  // velocity at the start of the step
  // The factor Π applies to the potentials: h² for BDF1, (2h/3)² for BDF2.
  double potential_scale = 0.0;
  // The point the integrator measures this step's velocity from, v = (q − q_ref)/c: q_t for
  // BDF1, q̂ = (4q_t − q_{t−1})/3 for BDF2 (null: q_t). Dissipative terms (friction) measure
  // their sliding from it.
  const VecX* q_ref = nullptr;
  // Whether q_t was given (the first step, or after set_state) rather than reached by the
  // previous step (or a substep of it); unknown: the term tells from what it last saw.
  std::optional<bool> fresh_state;
};

class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;
  virtual std::string name() const = 0;

  // Once per time step, before Newton starts (lagged quantities, e.g. friction bases).
  virtual void begin_step(const StepContext& /*ctx*/) {}
  // Whenever Newton accepts a new iterate (e.g. rebuild the active contact set).
  virtual void update(const VecX& /*q*/) {}
  // Re-evaluate lagged quantities at q (friction's normal forces and bases): once at the
  // Newton start when it is not q_t (islands start at their warm guess, near the
  // solution), and after Newton has converged at q (IPC's friction iterations). Returns true
  // when the term changed, so that the solver goes on minimising the changed Π from q.
  virtual bool refresh_lagged(const VecX& /*q*/) { return false; }
  // True when the term's force was not smooth over the last step (contact began or ended):
  // a multistep integrator (BDF2) then restarts from that state with one BDF1 step, since
  // its extrapolation through the kink adds energy (a BDF2 bounce returned above its drop).
  virtual bool broke_smoothness() const { return false; }

  virtual double value(const VecX& q) const = 0;
  virtual void add_gradient(const VecX& q, double scale, VecX& gradient) const = 0;
  virtual void add_hessian(const VecX& q, double scale, std::vector<BodyBlock>& blocks) const = 0;
  // Both at once (what a Newton iteration needs); terms that share work between the two
  // override it.
  virtual void add_gradient_and_hessian(const VecX& q, double scale, VecX& gradient,
                                        std::vector<BodyBlock>& blocks) const {
    add_gradient(q, scale, gradient);
    add_hessian(q, scale, blocks);
  }
  // The same, with rank-one parts of the Hessian as rows (HessianRow, scaled like blocks)
  // where the term has them; the default hands every part as blocks.
  virtual void add_gradient_and_hessian_rows(const VecX& q, double scale, VecX& gradient,
                                             std::vector<BodyBlock>& blocks,
                                             std::vector<HessianRow>& /*rows*/) const {
    add_gradient_and_hessian(q, scale, gradient, blocks);
  }

  // Largest alpha in (0, 1] such that the straight path q + t*dq, t in [0, alpha], stays
  // feasible (continuous collision detection). Terms without feasibility constraints
  // return 1.
  virtual double max_step(const VecX& /*q*/, const VecX& /*dq*/) const { return 1.0; }

  // A term whose force turns over a small speed scale (smoothed dry friction) tightens the
  // per-body Newton tolerances (velocity units) of the bodies it acts on: a step tolerance
  // above that speed cannot tell sticking from sliding. Called once per step, after
  // begin_step, and again after a refresh_lagged that changed the term; the vectors are
  // sized to the number of bodies, `radius` is each body's largest distance of a vertex
  // from its centre of mass (a speed ε at the surface is an affine rate ε / radius).
  virtual void limit_tolerances(VecX& /*tol_translation*/, VecX& /*tol_affine*/,
                                const std::vector<double>& /*radius*/) const {}
  // Sets flags[b] = 1 for the bodies whose share of the energy refresh_lagged may change
  // (they iterate again after a refresh that changed the term).
  virtual void mark_lagged_bodies(std::vector<unsigned char>& /*flags*/) const {}

  // ---- Optional: stiffness balanced at the start iterate (IPC's adaptive κ) -----------
  // True when, this step, the term sets a stiffness against the rest of Π at the Newton
  // start: the solver then calls balance_stiffness(q, grad_rest) with the gradient of
  // everything else (zero on bodies the solve does not move), before Newton's first
  // evaluation of Π.
  virtual bool balances_stiffness() const { return false; }
  virtual void balance_stiffness(const VecX& /*q*/, const VecX& /*grad_rest*/) {}
  // A parameter of the term's energy that update() may change within a step (IPC's adaptive
  // κ doubling): when it differs after an update, the solver evaluates Π again there.
  virtual double energy_parameter() const { return 0.0; }

  // ---- Optional: a majorising model --------------------------------------------------
  // A term whose energy can rise along a step far above what its Hessian's quadratic model
  // predicts (smoothed dry friction: along a sliding direction the exact model is linear, and
  // a step that stops the slide overshoots through the kink at zero sliding) may offer a
  // Hessian whose quadratic model bounds its energy from above along any step. The solver
  // asks for it (on = true) in the Newton iteration after a line search had to halve a step,
  // and for the exact Hessian otherwise (an island only converges on exact models).
  virtual void set_majorizing_model(bool /*on*/) {}

  // ---- Optional: splitting by body ---------------------------------------------------
  // A term made of elements that each involve one or two bodies (contact pairs, joints) can
  // say which bodies it couples. The solver then splits the bodies into independent groups
  // (islands) with their own line search and convergence, and bodies far from everything
  // keep the per-body fast path. `movable[b]` marks the bodies whose dofs the solve moves;
  // an element's energy belongs to the first movable body it involves (none: a constant,
  // dropped); a link is a pair of distinct movable bodies that share an element.
  // A term that returns false here couples every body with every other.
  virtual bool splits_by_body() const { return false; }
  // Adds each element's (unscaled) value at q to per_body[owner]; appends the links at q.
  virtual void add_body_values(const VecX& /*q*/, const std::vector<unsigned char>& /*movable*/,
                               VecX& /*per_body*/, std::vector<BodyLink>& /*links*/) const {}
  // Links of the state of the last update() and begin_step() (lagged elements included).
  virtual void body_links(const std::vector<unsigned char>& /*movable*/,
                          std::vector<BodyLink>& /*links*/) const {}
  // Per-body step bounds along q + t dq: bound[b] = min(bound[b], the max_step of the
  // elements involving b); near[b] = 1 when an element involving b may have a non-zero
  // energy somewhere on the path; links: pairs of movable bodies that may interact there.
  // bound and near come in sized to the number of bodies.
  virtual void body_max_steps(const VecX& /*q*/, const VecX& /*dq*/,
                              const std::vector<unsigned char>& /*movable*/, VecX& /*bound*/,
                              std::vector<unsigned char>& /*near*/,
                              std::vector<BodyLink>& /*links*/) const {}
  // How far from each other elements start to have energy (contact: d̂; 0: at contact or
  // never): bodies whose free solution strays from the checked path by more than a quarter
  // of it are checked again.
  virtual double reach() const { return 0.0; }
  // update(q) at a q that body_max_steps showed no element of the term reaches (the end of
  // a checked move with nothing near): a term may skip its proximity query there.
  virtual void update_clear(const VecX& q) { update(q); }
  // Sets flags[b] = 1 for the bodies in an element with energy at the last update().
  virtual void mark_active_bodies(std::vector<unsigned char>& /*flags*/) const {}
  // Sets flags[b] = 1 for every body the term may push at the last update() (lagged elements
  // included). A BDF1 step moves the bodies no term pushes along their exact parabola
  // (world_ballistic.cpp); the default marks every body, so a term that says nothing keeps
  // them all on implicit Euler.
  virtual void mark_forced_bodies(std::vector<unsigned char>& flags) const {
    std::fill(flags.begin(), flags.end(), static_cast<unsigned char>(1));
  }
};

}  // namespace abd
