// The World's coupled solve (world.h): what a step does when energy terms (contact, joints,
// user terms) are present.
//
//  1. Kinematic bodies go to their targets when that move is free of contact (CCD, the other
//     bodies at rest); the others are driven by a stiff spring this step (world.h).
//  2. Terms that split by body report, for the move of every body to its warm guess (the
//     last step's forces carried over; else its prediction), which bodies come within their
//     reach (links): linked bodies form islands. Bodies that nothing comes near run the
//     per-body Newton solve of the fast path and keep that free solution: they are solved
//     (start_iterate). Islands start from their warm guesses when the move there is clear,
//     else from where they are (IPC).
//  3. Projected Newton on the remaining islands in lockstep: one assembled system and one
//     contact query per iteration, but a CCD bound, Armijo line search and convergence test
//     per island; a converged island stops moving; islands merge whenever a term links them
//     (then they iterate again together). Each step's rotations are taken exactly
//     (rotation_exact_step), and an island whose steps Armijo keeps cutting gets
//     Levenberg–Marquardt damping. After a halving, the next iteration uses the terms'
//     majorising models (EnergyTerm::set_majorizing_model).
// All reductions run over bodies in index order, so results do not depend on threads.
// Steps 1-2: world_start.cpp; Π and step bounds: world_energy.cpp; the line search:
// world_line_search.cpp; islands: world_islands.cpp; constraints: world_constraints.cpp. Terms and constraints are seen only through
// EnergyTerm and Constraint (nothing here knows contact or joints).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>

#include "common/affine.h"
#include "common/finite.h"
#include "common/stopwatch.h"
#include "solver/body_math.h"
#include "solver/constrained_solve.h"
#include "solver/parallel.h"
#include "solver/world.h"
#include "solver/world_detail.h"

namespace abd {
using namespace world_detail;

namespace {

// The Newton step of one body with its rotation taken exactly. Newton's model linearises
// rotations: A + ΔA with ΔA = W A (W skew) leaves the rotations by O(|W|²), a stretch the
// stiff shape energy punishes, so the line search cuts every step touching a soft rotational
// mode (bodies rolling on contacts) and Newton creeps. Writing the increment of A as
// F = I + ΔA A⁻¹ = I + W + S (W skew, S symmetric), the step is replaced by one to
// A' = exp(W) (I + S) A, keeping the stretch S and the centre-of-mass motion of the Newton
// step, and agreeing with it to first order (so the converged step is unchanged to second
// order). The solver searches along the straight segment to that point.
Vec12 rotation_exact_step(const Vec12& x, const Vec12& dq, const Vec3& center) {
  const Mat3 A = affine_A(x);
  Mat3 A_inv;
  double det = 0.0;
  bool invertible = false;
  A.computeInverseAndDetWithCheck(A_inv, det, invertible, 1e-12);
  if (!invertible) return dq;
  const Mat3 dA = affine_A(dq);
  const Mat3 G = dA * A_inv;
  const Mat3 W = 0.5 * (G - G.transpose());
  const Mat3 S = 0.5 * (G + G.transpose());
  const Vec3 w(W(2, 1), W(0, 2), W(1, 0));
  const double theta = w.norm();
  if (!(theta > 1e-12) || theta > 1.0) return dq;  // nothing to correct, or too far out
  const Mat3 K = W / theta;
  const Mat3 R = Mat3::Identity() + std::sin(theta) * K + (1.0 - std::cos(theta)) * K * K;
  const Mat3 A_new = R * (Mat3::Identity() + S) * A;
  const Vec3 com_new = (A + dA) * center + affine_p(x) + dq.head<3>();
  return q_from(A_new, com_new - A_new * center) - x;
}

}  // namespace

// Terms that balance a stiffness against the rest of Π at the start iterate (IPC's adaptive
// κ: the barrier's gradient against everything else's, clamped to [κ_min, κ_max]; within the
// step, update() doubles it while a gap keeps closing below 1e-9 × the scene size. A κ that
// only ever grew ended at κ_max after the first hard landing, and the stiffer barrier took
// two to three times the Newton iterations from then on).
void World::balance_term_stiffness(double c2, const VecX& grad_bodies) {
  for (const auto& term : terms_) {
    if (!term->balances_stiffness()) continue;
    VecX grad_rest = grad_bodies;
    for (const auto& t : terms_)
      if (t != term) t->add_gradient(x_, c2, grad_rest);
    for (int b = 0; b < n_; ++b)
      if (!movable_[b]) grad_rest.segment<12>(12 * b).setZero();
    term->balance_stiffness(x_, grad_rest);
  }
}

void World::solve_coupled(double c2, StepDiagnostics& d) {
  const double h = scene_.dt;
  bool split = true;
  for (const auto& t : terms_) split = split && t->splits_by_body();
  const StepContext ctx{h, q_, q_dot_, c2, &q_hat_, fresh_state_};
  for (const auto& t : terms_) t->begin_step(ctx);

  x_free_.resize(12 * n_);
  trial_.resize(12 * n_);
  grad_.resize(12 * n_);
  dq_.resize(12 * n_);
  driven_.assign(n_, 0);
  parent_.resize(n_);
  std::iota(parent_.begin(), parent_.end(), 0);
  frozen_.assign(n_, 0);
  converged_.assign(n_, 0);
  pending_.assign(n_, 0);
  alpha_.setOnes(n_);
  damping_.setZero(n_);
  halved_.assign(n_, 0);
  bound_.setOnes(n_);

  // Where each body heads (its prediction; the target, for a driven kinematic body).
  x_free_ = x_pred_;

  // Newton tolerances per body: the settings', tightened by terms whose force turns over a
  // small speed (friction; EnergyTerm::limit_tolerances).
  tol_translation_.setConstant(n_, settings_.tol_translation);
  tol_affine_.setConstant(n_, settings_.tol_affine);
  for (const auto& t : terms_) t->limit_tolerances(tol_translation_, tol_affine_, radius_);

  // 1. Kinematic bodies; 2. the start iterate.
  x_ = q_;
  place_kinematic_bodies(d);
  movable_.assign(n_, 0);
  for (int b = 0; b < n_; ++b) movable_[b] = !constrained_[b];
  start_iterate(split, c2, d);
  lag_at_start();
  loosen_lagged_tolerances();

  // 3. Newton, island by island in lockstep.
  std::vector<BodyLink>& links = links_;
  double rest = 0.0;
  std::vector<std::uint8_t>& inactive = inactive_;
  inactive.assign(n_, 1);
  std::vector<int>& root = island_root_;  // island roots, for the parallel loops (island() writes)
  root.resize(n_);
  VecX& island_st = island_st_;
  VecX& island_sa = island_sa_;
  island_st.resize(n_);
  island_sa.resize(n_);
  std::string solver_used;
  bool all_done = false;
  int free_newton = 0;  // iterations of the bodies whose free solution stands
  for (int b = 0; b < n_; ++b) {
    if (!movable_[b]) continue;
    if (frozen_[island(b)])
      free_newton = std::max(free_newton, free_iterations_[b]);
    else
      ++d.coupled_bodies;
  }

  // Without terms that act by proximity (contact), Π's values serve the line search only:
  // they are evaluated when a line search runs (stale: body_E_ and rest are not Π at x_).
  double reach = 0.0;
  for (const auto& t : terms_) reach = std::max(reach, t->reach());
  const bool lazy_energies = reach == 0.0;
  bool stale = false;
  auto energies_at_x = [&]() {  // Π per body and the rest at x_, and the links they find
    links.clear();
    rest = body_energies(x_, c2, body_E_, links);
    for (const BodyLink& l : links) merge_islands(l.a, l.b);
    stale = false;
  };
  auto x_moved = [&]() {  // Π's values at x_ now, or when a line search wants them
    if (lazy_energies)
      stale = true;
    else
      energies_at_x();
  };

  int refreshes_left = settings_.friction_iterations;
  // Whether this iteration asks the terms for their majorising models: after a line search
  // that had to halve a step. In the landing heap, friction's exact model (linear along a
  // sliding direction) let Newton steps stop slides past zero; friction then held 85% of the
  // excess of Π over its linear prediction at the failing Armijo trials, its rise 78 times
  // (median) what the local quadratic predicted, and halvings cut one shared α for 60-body
  // islands. Majorising in every iteration removed 89% of the failing Armijo trials but
  // converged only linearly (IRLS) on slow slides, for as many iterations in all; asked for
  // only after a halving, it cures the overshoot and Newton keeps its exact model otherwise
  // (heap of 100, 120 steps, seeds 0-2: 26,968 -> 15,037 iterations).
  bool majorize = false;
  for (int it = 0; it < settings_.max_newton_iterations; ++it) {
    int n_active = 0;
    for (int b = 0; b < n_; ++b) {
      inactive[b] = !(movable_[b] && !frozen_[island(b)]);
      n_active += !inactive[b];
    }
    if (n_active == 0 && refreshes_left > 0 && it > 0) {
      // Converged: lagged quantities (friction's normal forces and bases) are evaluated
      // again at the solution and Newton goes on from there (IPC's friction iterations).
      --refreshes_left;
      bool changed = false;
      for (const auto& t : terms_) changed = t->refresh_lagged(x_) || changed;
      // The bodies the refresh changed, and those only converged to the first solve's
      // looser tolerances, iterate again (world_friction_phases.cpp).
      if (retighten_after_refresh(changed)) {
        if (changed) energies_at_x();
        for (int b = 0; b < n_; ++b) {
          inactive[b] = !(movable_[b] && !frozen_[island(b)]);
          n_active += !inactive[b];
        }
      }
    }
    if (n_active == 0) {
      all_done = true;
      break;
    }
    if (it == 0) {
      for (int b = 0; b < n_; ++b)
        if (!inactive[b] && island(b) == b) ++d.islands;
    }
    d.newton_iterations = it + 1;
    d.total_body_iterations += n_active;

    // Assemble and solve.
    for (const auto& t : terms_) t->set_majorizing_model(majorize);
    Lap lap;  // the step profile's sections (StepDiagnostics::time_*)
    for (int b = 0; b < n_; ++b) root[b] = island(b);
    system_.reset(n_, inactive);
    parallel_for(n_, threads_, [&](int b) {
      Mat12& H = system_.diagonal(b);
      if (inactive[b]) {
        H.setZero();
        grad_.segment<12>(12 * b).setZero();
        return;
      }
      Vec12 g;
      body_energy(b, x_.segment<12>(12 * b), c2, &g, &H);
      const double nu = damping_[root[b]];
      if (nu > 0.0) H += nu * mass_matrix_[b];
      grad_.segment<12>(12 * b) = g;
    });
    if (it == 0) {
      // κ from the gradient balance at the start iterate (grad_ holds the bodies' own part
      // of ∇Π now), then Π at the start with that κ.
      balance_term_stiffness(c2, grad_);
      x_moved();
    }
    bool constrained = false;
    for (int b = 0; b < n_ && !constraints_.empty(); ++b)
      constrained = constrained || (jointed_[b] && !inactive[b]);
    blocks_.clear();
    hessian_rows_.clear();
    for (const auto& t : terms_)
      t->add_gradient_and_hessian_rows(x_, c2, grad_, blocks_, hessian_rows_);
    for (int b = 0; b < n_; ++b)
      if (inactive[b]) grad_.segment<12>(12 * b).setZero();
    if (!all_finite(grad_)) throw SolverError("the gradient of Π is not finite");
    system_.add_blocks(blocks_);
    // The KKT solves take rank-one rows as rows; the other solvers as blocks.
    system_.add_rows(hessian_rows_, constrained);
    system_.finalize();
    d.time_assembly += lap.split();
    d.residual = grad_.cwiseAbs().maxCoeff();

    rhs_ = -grad_;
    const VecX& rhs = rhs_;
    std::vector<ConstraintRow>& rows = newton_rows_;
    rows.clear();
    if (constrained) newton_constraint_rows(rows);
    LinearSolverKind kind = settings_.linear_solver;
    const bool per_body = kind == LinearSolverKind::kAuto && !system_.coupled() && !constrained;
    if (kind == LinearSolverKind::kAuto)
      kind = 12 * n_active <= settings_.direct_max_dofs ? LinearSolverKind::kDirect
                                                        : LinearSolverKind::kPCG;
    if (constrained) {
      // Exact constraints: the KKT system (sparse direct; constrained_solve.h).
      solver_used = "direct";
      kkt_newton_.solve(system_, rows, rhs, dq_);
    } else if (per_body) {
      solver_used = "block_diagonal";
      const int bad = system_.solve_block_diagonal(rhs, dq_, threads_);
      if (bad >= 0)
        throw SolverError("Newton failed at step " + std::to_string(step_count_) + ": the 12x12 "
                          "Newton matrix of " + describe(bad) + " is not positive definite" +
                          (external_kinetic_[bad] ? " (external_kinetic = 1 and no energy term "
                                                    "holds it)"
                                                  : ""));
    } else if (kind == LinearSolverKind::kDirect) {
      solver_used = "direct";
      d.symbolic_analyses += system_.solve_direct(rhs, dq_);
    } else {
      solver_used = "pcg";
      d.pcg_iterations += system_.solve_pcg(rhs, dq_, settings_.pcg_tolerance,
                                            settings_.pcg_max_iterations, threads_);
    }
    if (!all_finite(dq_)) throw SolverError("the Newton direction is not finite");
    d.time_linear_solve += lap.split();

    // Per-island convergence test on the direction, relative to each body's tolerances.
    island_st.setZero();
    island_sa.setZero();
    VecX& island_ratio = island_ratio_;
    island_ratio.setZero(n_);
    d.step_translation = d.step_affine = 0.0;
    for (int b = 0; b < n_; ++b) {
      if (inactive[b]) continue;
      double st, sa;
      step_sizes(dq_.segment<12>(12 * b), h, st, sa);
      const int r = island(b);
      island_st[r] = std::max(island_st[r], st);
      island_sa[r] = std::max(island_sa[r], sa);
      island_ratio[r] = std::max({island_ratio[r], st / tol_translation_[b], sa / tol_affine_[b]});
      note_tight_convergence(b, st, sa);
      d.step_translation = std::max(d.step_translation, st);
      d.step_affine = std::max(d.step_affine, sa);
    }
    // An undamped island converges when its step is within tolerance. A damped one solves
    // (H + νM) Δq = −g with H ⪰ M, so its undamped Newton step is at most (1 + ν) times
    // longer: it converges when even that bound is within tolerance (this ends iterations
    // that stagnate at round-off with the damping still raised). A step of majorising models
    // bounds nothing (their Hessians may be far stiffer than Π's): no island converges on it.
    for (int b = 0; b < n_; ++b)
      if (!inactive[b] && island(b) == b)
        converged_[b] = !majorize && island_ratio[b] * (1.0 + damping_[b]) <= 1.0;

    // Rotations taken exactly (see rotation_exact_step); an island for which that is not
    // a descent direction keeps the plain Newton step. Constrained bodies keep the straight
    // step (it keeps linear rows exact): when every moving body is one (an articulation),
    // there is nothing to do.
    auto rotates = [&](int b) { return !inactive[b] && !(!jointed_.empty() && jointed_[b]); };
    bool any_rotates = false;
    for (int b = 0; b < n_ && !any_rotates; ++b) any_rotates = rotates(b);
    VecX& dq_newton = dq_newton_;
    if (any_rotates) dq_newton = dq_;
    parallel_for(
        any_rotates ? n_ : 0, threads_,
        [&](int b) {
          if (!rotates(b)) return;
          dq_.segment<12>(12 * b) = rotation_exact_step(x_.segment<12>(12 * b),
                                                        dq_newton.segment<12>(12 * b),
                                                        dyadic_[b].m_x_bar / dyadic_[b].m);
        },
        kLightLoop);
    if (any_rotates) {
      VecX& slope_exact = slope_exact_;
      slope_exact.setZero(n_);
      for (int b = 0; b < n_; ++b)
        if (!inactive[b])
          slope_exact[island(b)] += grad_.segment<12>(12 * b).dot(dq_.segment<12>(12 * b));
      for (int b = 0; b < n_; ++b)
        if (!inactive[b] && !(slope_exact[island(b)] < 0.0))
          dq_.segment<12>(12 * b) = dq_newton.segment<12>(12 * b);
    }

    // Step bounds (CCD) and links along the direction.
    std::vector<unsigned char>& near = near_;
    links.clear();
    lap.split();
    const double global = step_bounds(x_, dq_, movable_, near, links);
    d.time_ccd += lap.split();
    for (const BodyLink& l : links) merge_islands(l.a, l.b);
    // Islands moving now (a frozen island merged into an active one moves with it).
    for (int b = 0; b < n_; ++b) inactive[b] = !(movable_[b] && !frozen_[island(b)]);
    for (int b = 0; b < n_; ++b)
      if (!inactive[b] && island(b) == b) alpha_[b] = 1.0;
    for (int b = 0; b < n_; ++b)
      if (!inactive[b]) {
        const int r = island(b);
        alpha_[r] = std::min({alpha_[r], bound_[b], global});
      }
    for (int b = 0; b < n_; ++b)
      if (!inactive[b] && island(b) == b) {
        d.min_term_max_step = std::min(d.min_term_max_step, alpha_[b]);
        d.line_search_ccd_cuts += alpha_[b] < 1.0;
        if (alpha_[b] < 1.0) alpha_[b] *= settings_.ccd_safety;
        pending_[b] = 1;
        halved_[b] = 0;
      }

    // A step that converges every moving island, whole (no step bound cut it), is taken
    // without the line search when Π's values are not needed for anything else: it is within
    // the Newton tolerances of the solution, where an Armijo test compares round-off-sized
    // changes of Π (it could only keep such an island where it is, alpha 0, or cut the step
    // and iterate once more).
    bool take_whole = lazy_energies;
    for (int b = 0; b < n_ && take_whole; ++b)
      if (!inactive[b]) take_whole = converged_[island(b)] && alpha_[island(b)] == 1.0;
    if (take_whole) {
      trial_ = x_;
      for (int b = 0; b < n_; ++b)
        if (!inactive[b]) trial_.segment<12>(12 * b) += dq_.segment<12>(12 * b);
      stale = true;
    } else {
      if (stale) energies_at_x();
      double rest_new = rest;
      const int r = armijo_search_islands(c2, split, rest, inactive, rest_new, d);
      if (r >= 0) {
        std::ostringstream msg;
        msg << "Newton failed at step " << step_count_ << " (t = " << time_
            << "): the line search found no decrease of Π in "
            << settings_.max_line_search_iterations << " halvings (iteration " << it + 1 << ", "
            << describe(r) << " and the bodies coupled to it, step bound "
            << std::min(bound_[r], global) << ", last step " << island_st[r] << " m/s, "
            << island_sa[r] << " 1/s)";
        throw SolverError(msg.str());
      }
      body_E_.swap(body_E_new_);
      rest = rest_new;
    }
    judge_island_steps(inactive, island_ratio, d);
    majorize = false;
    for (int r = 0; r < n_ && !majorize; ++r)
      majorize = !inactive[r] && island(r) == r && halved_[r];
    d.time_line_search += lap.split();
    x_.swap(trial_);
    if (nonlinear_constraints_ && project_constraints()) {
      // Back onto the constraints that the linearised step only met to first order (Π
      // again where that moved the iterate).
      x_moved();
    }

    // Accept: terms see the new iterate; islands they now link iterate again together.
    std::vector<double>& parameters = term_parameters_;
    parameters.clear();
    for (const auto& t : terms_) parameters.push_back(t->energy_parameter());
    for (const auto& t : terms_) t->update(x_);
    d.time_contact_update += lap.split();
    for (int r = 0; r < n_; ++r)
      if (!inactive[r] && island(r) == r && converged_[r]) frozen_[r] = 1;
    links.clear();
    for (const auto& t : terms_) t->body_links(movable_, links);
    for (const BodyLink& l : links) merge_islands(l.a, l.b);
    bool reparametrised = false;  // e.g. adaptive κ doubled: Π changed
    for (std::size_t k = 0; k < terms_.size(); ++k)
      reparametrised = reparametrised || terms_[k]->energy_parameter() != parameters[k];
    if (reparametrised) x_moved();
  }
  if (!all_done) {
    bool remaining = false;
    for (int b = 0; b < n_ && !remaining; ++b) remaining = movable_[b] && !frozen_[island(b)];
    if (remaining) {
      std::ostringstream msg;
      msg << "Newton did not converge in " << settings_.max_newton_iterations
          << " iterations at step " << step_count_ << " (t = " << time_ << "): last step "
          << d.step_translation << " m/s, " << d.step_affine << " 1/s (tolerances "
          << settings_.tol_translation << ", " << settings_.tol_affine << "), residual "
          << d.residual;
      throw SolverError(msg.str());
    }
  }
  for (const auto& t : terms_) t->set_majorizing_model(false);
  d.converged = true;
  remember_warm_start(c2);
  d.newton_iterations = std::max(d.newton_iterations, free_newton);
  d.linear_solver = solver_used.empty() ? "block_diagonal" : solver_used;

  // Driven kinematic bodies: how far each vertex was left from its target.
  for (int b = 0; b < n_; ++b) {
    if (!driven_[b]) continue;
    const Vec12 lag = x_.segment<12>(12 * b) - q_tilde_.segment<12>(12 * b);
    double worst = lag.head<3>().norm();
    if (!scene_.geometries.empty()) {
      const MatX3& rest_vertices = scene_.geometries[scene_.bodies[b].geometry].rest_vertices;
      for (Eigen::Index v = 0; v < rest_vertices.rows(); ++v)
        worst = std::max(worst, affine_point(lag, rest_vertices.row(v).transpose()).norm());
    }
    if (worst > d.kinematic_lag) {
      d.kinematic_lag = worst;
      d.kinematic_lag_body = b;
    }
  }

  if (!settings_.energies) return;  // not asked for (SolverSettings::energies)
  std::vector<double>& parts = energy_parts_;
  const double E = total_energy(x_, c2, &parts);
  d.energies = {{"kinetic", parts[0]}, {"shape", parts[1]}};
  if (d.driven_bodies > 0) d.energies.emplace_back("kinematic_drive", parts[2]);
  for (std::size_t k = 0; k < terms_.size(); ++k)
    d.energies.emplace_back(terms_[k]->name(), parts[3 + k]);
  d.energies.emplace_back("total", E);
}

}  // namespace abd
