#include "solver/world.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/affine.h"
#include "common/finite.h"
#include "contact/ipc_contact_term.h"
#include "solver/body_math.h"
#include "solver/parallel.h"
#include "solver/world_detail.h"

namespace abd {
using namespace world_detail;

World::World(const SceneData& scene, const SolverSettings& settings)
    : scene_(scene), settings_(settings), n_(static_cast<int>(scene.bodies.size())),
      shape_(scene, settings.project_psd) {
  require(std::isfinite(scene.dt) && scene.dt > 0.0,
          "dt must be a positive finite number, got " + std::to_string(scene.dt));
  require(scene.gravity.allFinite(), "gravity must be finite");
  require(settings.tol_translation > 0.0 && settings.tol_affine > 0.0,
          "Newton tolerances must be positive");
  require(settings.max_newton_iterations >= 1, "max_newton_iterations must be >= 1");
  require(settings.friction_iterations >= 0, "friction_iterations must be >= 0");
  require(settings.max_line_search_iterations >= 1, "max_line_search_iterations must be >= 1");
  require(settings.ccd_safety > 0.0 && settings.ccd_safety <= 1.0, "ccd_safety must be in (0, 1]");
  require(settings.armijo_c >= 0.0 && settings.armijo_c < 1.0, "armijo_c must be in [0, 1)");
  require(settings.pcg_tolerance > 0.0 && settings.pcg_max_iterations >= 1,
          "PCG tolerance and iteration cap must be positive");
  require(settings.integrator == Integrator::kBDF1 || settings.integrator == Integrator::kBDF2,
          "unknown integrator");
  threads_ = resolve_threads(settings.num_threads);

  const int ng = static_cast<int>(scene.geometries.size());
  q_.resize(12 * n_);
  q_dot_.resize(12 * n_);
  dyadic_.resize(n_);
  mass_matrix_.resize(n_);
  mass_floor_.resize(n_);
  fixed_.resize(n_);
  dynamic_.resize(n_);
  external_kinetic_.resize(n_);
  kinematic_.assign(n_, 0);
  driven_.assign(n_, 0);
  for (int b = 0; b < n_; ++b) {
    const BodyData& body = scene.bodies[b];
    require(ng == 0 || (body.geometry >= 0 && body.geometry < ng),
            describe(b) + ": geometry index " + std::to_string(body.geometry) + " out of range");
    require(body.q.allFinite(), describe(b) + ": initial state (transform) is not finite");
    require(body.q_dot.allFinite(), describe(b) + ": initial velocity is not finite");
    require(std::isfinite(body.kappa) && body.kappa >= 0.0,
            describe(b) + ": kappa must be finite and >= 0");
    require(std::isfinite(body.volume) && body.volume > 0.0,
            describe(b) + ": volume must be positive and finite");
    require(std::isfinite(body.mass) && body.mass > 0.0 && body.mass_x_bar.allFinite() &&
                body.mass_x_bar_x_bar.allFinite(),
            describe(b) + ": dyadic mass must be finite with abd_mass > 0");
    DyadicMass dm;
    dm.m = body.mass;
    dm.m_x_bar = body.mass_x_bar;
    dm.S = 0.5 * (body.mass_x_bar_x_bar + body.mass_x_bar_x_bar.transpose());
    // M is SPD iff m > 0 and the central second moment S − m x̄ x̄ᵀ/m is positive definite.
    const Mat3 central = dm.S - dm.m_x_bar * dm.m_x_bar.transpose() / dm.m;
    const Vec3 ev = Eigen::SelfAdjointEigenSolver<Mat3>(central, Eigen::EigenvaluesOnly).eigenvalues();
    require(ev[0] > 1e-12 * std::max(ev[2], 0.0) && ev[2] > 0.0,
            describe(b) + ": singular mass matrix (the central second moment S - m x̄ x̄ᵀ/m has "
                          "eigenvalues " + std::to_string(ev[0]) + ", " + std::to_string(ev[1]) +
                          ", " + std::to_string(ev[2]) +
                          "); a flat or degenerate body needs a thickness");
    dyadic_[b] = dm;
    mass_matrix_[b] = dm.matrix();
    mass_floor_[b] =
        0.5 * Eigen::SelfAdjointEigenSolver<Mat12>(mass_matrix_[b], Eigen::EigenvaluesOnly)
                  .eigenvalues()[0];
    q_.segment<12>(12 * b) = body.q;
    q_dot_.segment<12>(12 * b) = body.is_fixed ? Vec12::Zero() : body.q_dot;
    fixed_[b] = body.is_fixed;
    dynamic_[b] = body.is_dynamic;
    external_kinetic_[b] = body.external_kinetic;
  }
  radius_.assign(n_, 1.0);
  extent_.assign(n_, 0.0);
  for (int b = 0; b < n_; ++b) {
    if (scene.geometries.empty()) break;
    const MatX3& rest = scene.geometries[scene.bodies[b].geometry].rest_vertices;
    const Vec3 center = dyadic_[b].m_x_bar / dyadic_[b].m;
    double r = 0.0;
    for (Eigen::Index v = 0; v < rest.rows(); ++v) {
      r = std::max(r, (rest.row(v).transpose() - center).norm());
      extent_[b] = std::max(extent_[b], rest.row(v).norm());
    }
    if (r > 0.0) radius_[b] = r;
  }
  kinematic_target_ = q_;
  q_prev_ = q_;
  q_dot_prev_ = q_dot_;
}

std::string World::describe(int body) const {
  return "body " + std::to_string(body) + " (geometry " +
         std::to_string(scene_.bodies[body].geometry) + ")";
}

int World::check_body(int body) const {
  if (body < 0 || body >= n_)
    throw std::out_of_range("body index " + std::to_string(body) + " out of range [0, " +
                            std::to_string(n_) + ")");
  return body;
}

void World::add_term(std::shared_ptr<EnergyTerm> term) {
  require(term != nullptr, "add_term: null energy term");
  terms_.push_back(std::move(term));
}

void World::add_constraint(std::shared_ptr<Constraint> constraint) {
  require(constraint != nullptr, "add_constraint: null constraint");
  constraints_.push_back(std::move(constraint));
}

void World::set_state(const VecX& q, const VecX& q_dot) {
  require(q.size() == 12 * n_ && q_dot.size() == 12 * n_,
          "set_state: q and q_dot must have 12 * n_bodies = " + std::to_string(12 * n_) +
              " entries");
  require(q.allFinite() && q_dot.allFinite(), "set_state: state is not finite");
  q_ = q;
  q_dot_ = q_dot;
  for (int b = 0; b < n_; ++b) {
    if (fixed_[b]) q_dot_.segment<12>(12 * b).setZero();
    if (kinematic_[b]) kinematic_target_.segment<12>(12 * b) = q_.segment<12>(12 * b);
  }
  has_history_ = false;
  restitution_.reset();
  fresh_state_ = true;
  warm_valid_.clear();  // the last solve's forces say nothing about this state
}

void World::set_time(double t) {
  require(std::isfinite(t), "set_time: time must be finite");
  time_ = time_base_ = t;
  step_base_ = step_count_;
}

void World::set_kinematic_target(int body, const Vec12& q_target) {
  check_body(body);
  require(!fixed_[body], describe(body) + " is fixed and cannot be driven kinematically");
  require(q_target.allFinite(), describe(body) + ": kinematic target is not finite");
  kinematic_[body] = 1;
  kinematic_target_.segment<12>(12 * body) = q_target;
  if (contact_) contact_->set_scripted(body, true);
}

void World::release_kinematic(int body) {
  check_body(body);
  if (!kinematic_[body]) return;
  kinematic_[body] = 0;
  if (!contact_) return;
  // Back to the dynamics: it now collides with other scripted bodies and the ground, so the
  // state must be a valid contact configuration for it.
  contact_->set_scripted(body, false);
  try {
    contact_->check_initial(q_);
  } catch (const std::invalid_argument& e) {
    kinematic_[body] = 1;
    contact_->set_scripted(body, true);
    throw std::invalid_argument("cannot release " + describe(body) + " from its kinematic "
                                "drive here: " + e.what());
  }
}

// q̂, q̃, the constrained mask and the Newton predictor x_pred for this step (c = h, or
// 2h/3 for BDF2).
//
// Predictor: q̃ moves A along Ȧ, which for a rotating body leaves the rotations by
// O(h²|Ȧ|²); a stiff shape energy then spends Newton iterations just pulling it back. We
// write Ã = F A_t and replace the increment F by one Björck step F (3I − FᵀF)/2, which
// removes F's departure from a rotation to second order while keeping A_t's own deformation;
// p is shifted so that the centre of mass stays where q̃ puts it. Only applied to modest
// increments (|FᵀF − I| < 0.1), where the iteration contracts. Only the start point
// changes: Newton still minimises Π. The coupled solve orthogonalises in start_iterate,
// only the predictions a body may start from (orthogonalise false here).
void World::predict_body(int b, double c, bool bdf2, bool orthogonalise) {
  const Vec3 g_step = c * c * scene_.gravity;
  const auto qt = q_.segment<12>(12 * b);
  auto q_hat = q_hat_.segment<12>(12 * b);
  auto q_tilde = q_tilde_.segment<12>(12 * b);
  constrained_[b] = fixed_[b] || kinematic_[b];
  if (bdf2) {
    q_hat = (4.0 * qt - q_prev_.segment<12>(12 * b)) / 3.0;
  } else {
    q_hat = qt;
  }
  if (fixed_[b]) {
    q_tilde = qt;
  } else if (kinematic_[b]) {
    q_tilde = kinematic_target_.segment<12>(12 * b);
  } else if (dynamic_[b]) {
    const Vec12 v_hat = bdf2 ? Vec12((4.0 * q_dot_.segment<12>(12 * b) -
                                      q_dot_prev_.segment<12>(12 * b)) / 3.0)
                             : Vec12(q_dot_.segment<12>(12 * b));
    q_tilde = q_hat + c * v_hat;
    q_tilde.head<3>() += g_step;
  } else {  // quasi-static: no velocity term
    q_tilde = qt;
    q_tilde.head<3>() += g_step;
  }
  x_pred_.segment<12>(12 * b) = q_tilde;
  if (orthogonalise && !constrained_[b]) orthogonalise_prediction(b);
}

// x_pred_ of body b from q̃ to q̃ with its increment of A orthogonalised (predict_body).
void World::orthogonalise_prediction(int b) {
  const Vec12 pred = x_pred_.segment<12>(12 * b);
  const auto qt = q_.segment<12>(12 * b);
  const Mat3 A = affine_A(pred);
  Mat3 At_inv;
  double det = 0.0;
  bool invertible = false;
  affine_A(qt).computeInverseAndDetWithCheck(At_inv, det, invertible, 1e-12);
  const Mat3 F = A * At_inv;
  const Mat3 FtF = F.transpose() * F;
  if (invertible && (FtF - Mat3::Identity()).cwiseAbs().maxCoeff() < 0.1) {
    const Mat3 A_orth = 0.5 * F * (3.0 * Mat3::Identity() - FtF) * affine_A(qt);
    const Vec3 center = dyadic_[b].m_x_bar / dyadic_[b].m;
    x_pred_.segment<12>(12 * b) = q_from(A_orth, affine_p(pred) - (A_orth - A) * center);
  }
}

// Velocity at the end of the step, from x_ (BDF1: (x − q_t)/h; BDF2: (x − q̂)/c).
void World::finish_body(int b, double c) {
  auto v = q_dot_new_.segment<12>(12 * b);
  const auto x = x_.segment<12>(12 * b);
  if (fixed_[b]) {
    v.setZero();
  } else if (dynamic_[b] || kinematic_[b]) {
    v = (x - q_hat_.segment<12>(12 * b)) / c;
  } else {
    v = (x - q_.segment<12>(12 * b)) / scene_.dt;
  }
}

// One step of length h: solved once, accepted if its straight-line motion from q_t is free
// of contact and no body inverts or flattens (step_rejection); otherwise (or when Newton
// fails) redone as substeps (world_substeps.cpp). The state is unchanged when it throws.
const StepDiagnostics& World::step() {
  const auto t_start = std::chrono::steady_clock::now();
  const double h = scene_.dt;
  StepDiagnostics d = fresh_step();
  d.step = step_count_;
  if (contact_ && contact_->has_restitution()) {
    step_q_t_ = q_;
    step_q_dot_t_ = q_dot_;
  }
  const std::string failure = try_step(d);
  if (failure.empty()) {
    commit_step();
    remember_gap(d);
  } else {
    // The rejected solve's time, for the step's discarded_time (advance_in_substeps).
    d.wall_time =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    advance_in_substeps(failure, d);
  }
  apply_restitution(d);
  ++step_count_;
  time_ = time_base_ + static_cast<double>(step_count_ - step_base_) * h;

  d.time = time_;
  d.wall_time =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  steps_.push_back(std::move(d));
  reported_ = std::min(reported_ + 1, history_limit_);
  trim_steps();
  return steps_.back();
}

// Solves one step of length scene_.dt from the current state into x_ and q_dot_new_ (the
// state itself is not changed: commit_step does that).
void World::solve_step(StepDiagnostics& d) {
  const double h = scene_.dt;
  const bool bdf2 = settings_.integrator == Integrator::kBDF2 && has_history_;
  const double c = bdf2 ? 2.0 * h / 3.0 : h;
  const double c2 = c * c;
  for (VecX* v : {&q_hat_, &q_tilde_, &x_pred_, &x_, &q_dot_new_}) v->resize(12 * n_);
  constrained_.resize(n_);
  d.integrator_order = bdf2 ? 2 : 1;

  if (terms_.empty() && constraints_.empty() &&
      settings_.linear_solver == LinearSolverKind::kAuto) {
    step_per_body(c, bdf2, d);  // predictions, Newton and velocities in one parallel loop
    warm_valid_.clear();        // no solve_coupled to remember its forces
  } else {
    parallel_for(n_, threads_, [&](int b) { predict_body(b, c, bdf2, false); });
    const double broad_phase_before = contact_ ? contact_->broad_phase_seconds() : 0.0;
    solve_coupled(c2, d);
    if (contact_) d.time_broad_phase = contact_->broad_phase_seconds() - broad_phase_before;
    parallel_for(n_, threads_, [&](int b) { finish_body(b, c); });
  }
  if (bdf2)
    ballistic_.assign(n_, 0);
  else
    shift_ballistic_bodies();
  contact_diagnostics(d);
  constraint_diagnostics(d);
  if (!all_finite(x_) || !all_finite(q_dot_new_))
    throw SolverError("the step produced a non-finite state");
}

// The solved step (x_, q_dot_new_) becomes the state.
void World::commit_step() {
  q_prev_.swap(q_);
  q_dot_prev_.swap(q_dot_);
  q_.swap(x_);
  q_dot_.swap(q_dot_new_);
  has_history_ = true;
  for (const auto& t : terms_) has_history_ = has_history_ && !t->broke_smoothness();
  for (const auto& c : constraints_) c->end_step(q_, q_dot_);
  fresh_state_ = false;
}

const StepDiagnostics& World::diagnostics() const {
  static const StepDiagnostics before_first_step;
  return steps_.empty() ? before_first_step : steps_.back();
}

World::HistoryView World::history() const {
  return {steps_.end() - static_cast<std::ptrdiff_t>(reported_), steps_.end()};
}

void World::set_history_limit(std::size_t limit) {
  history_limit_ = limit;
  reported_ = std::min(reported_, limit);
  trim_steps();
}

void World::clear_history() {
  reported_ = 0;
  trim_steps();
}

void World::trim_steps() {
  // The last step stays (diagnostics() reads it) even when no step is reported.
  const std::size_t kept = std::max<std::size_t>(history_limit_, 1);
  while (steps_.size() > kept) {
    spare_alphas_.swap(steps_.front().line_search_alphas);
    spare_energies_.swap(steps_.front().energies);
    steps_.pop_front();
  }
}

StepDiagnostics World::fresh_step() {
  StepDiagnostics d;
  d.line_search_alphas.swap(spare_alphas_);
  d.energies.swap(spare_energies_);
  d.line_search_alphas.clear();
  d.energies.clear();
  return d;
}

// ---------------------------------------------------------------------------------------
// Per-body Newton on ½|x − q̃|²_M + c² Ψ (no terms), from x. Used by the fast path and as
// the free solution the coupled solve starts from.
void World::newton_body(int b, double c2, Vec12& x, BodyNewton& r,
                        std::vector<double>* alphas) const {
  const double h = scene_.dt;
  const int max_it = settings_.max_newton_iterations;
  const DyadicMass& dm = dyadic_[b];
  const bool kinetic = !external_kinetic_[b];
  const Vec12 qt = q_tilde_.segment<12>(12 * b);
  auto energy = [&](const Vec12& y, double& ek, double& es) {
    ek = kinetic ? mass_quadratic(dm, y - qt) : 0.0;
    es = shape_.body_value(b, y);
    return ek + c2 * es;
  };
  double E = energy(x, r.kinetic, r.shape);
  for (int it = 0; it < max_it; ++it) {
    Vec12 g;
    Mat12 H;
    if (kinetic) {
      g = mass_times(dm, x - qt);
      H = mass_matrix_[b];
    } else {
      g.setZero();
      H.setZero();
    }
    shape_.add_body_derivatives(b, x, c2, g, H);
    r.residual = g.cwiseAbs().maxCoeff();
    r.iterations = it + 1;
    Vec12 dq;
    if (!cholesky_solve<12>(H, Vec12(-g), dq)) {
      r.status = kSingular;
      break;
    }
    if (!dq.allFinite()) {
      r.status = kNonFinite;
      break;
    }
    step_sizes(dq, h, r.step_translation, r.step_affine);
    const bool small =
        r.step_translation <= settings_.tol_translation && r.step_affine <= settings_.tol_affine;
    const double slope = g.dot(dq);
    double alpha = 1.0;
    bool accepted = false;
    double ek = 0.0, es = 0.0, E_new = E;
    for (int ls = 0; ls < settings_.max_line_search_iterations; ++ls) {
      E_new = energy(x + alpha * dq, ek, es);
      if (E_new <= E + settings_.armijo_c * alpha * slope + roundoff(E)) {
        accepted = true;
        break;
      }
      alpha *= 0.5;
    }
    // Converged: a small step that the line search took whole (a shortened step says the
    // quadratic model is off, so a small direction proves nothing), or a small step that
    // no longer decreases Π at all, or one far below tolerance (round-off: there the
    // Armijo test is noise).
    const double ratio = std::max(r.step_translation / settings_.tol_translation,
                                  r.step_affine / settings_.tol_affine);
    const bool converged = small && (!accepted || alpha == 1.0 || ratio <= kRoundoffStep);
    if (accepted) {
      x += alpha * dq;
      E = E_new;
      r.kinetic = ek;
      r.shape = es;
      if (alphas) (*alphas)[it] = std::min((*alphas)[it], alpha);
    } else if (!small) {
      r.status = kLineSearch;
      break;
    }
    if (converged) {
      r.status = kConverged;
      break;
    }
  }
  if (r.status == kRunning) r.status = kMaxIterations;
}

// ---------------------------------------------------------------------------------------
// Fast path: no term couples bodies, so Π is a sum of per-body potentials and every body
// runs its own Newton iteration (12x12 Cholesky, own line search), in parallel: one parallel
// loop per step; results do not depend on which thread ran which body.
void World::step_per_body(double c, bool bdf2, StepDiagnostics& d) {
  d.linear_solver = "block_diagonal";
  const double c2 = c * c;
  const int max_it = settings_.max_newton_iterations;
  std::vector<BodyNewton> result(n_);
  // Smallest accepted alpha per iteration, per thread (min is exact in any order).
  std::vector<std::vector<double>> alphas(threads_, std::vector<double>(max_it, 2.0));

  parallel_for_slot(n_, threads_, [&](int b, int slot) {
    predict_body(b, c, bdf2, true);
    BodyNewton& r = result[b];
    if (constrained_[b]) {
      r.status = kConverged;
      r.shape = shape_.body_value(b, q_tilde_.segment<12>(12 * b));
      x_.segment<12>(12 * b) = q_tilde_.segment<12>(12 * b);
      finish_body(b, c);
      return;
    }
    Vec12 x = x_pred_.segment<12>(12 * b);
    newton_body(b, c2, x, r, &alphas[slot]);
    x_.segment<12>(12 * b) = x;
    finish_body(b, c);
  });

  // Report the first failing body (lowest index: the same whatever the thread count).
  for (int b = 0; b < n_; ++b) {
    const BodyNewton& r = result[b];
    if (r.status == kConverged) continue;
    std::ostringstream msg;
    msg << "Newton failed for " << describe(b) << " at step " << step_count_ << " (t = " << time_
        << "): ";
    switch (r.status) {
      case kSingular:
        msg << "its 12x12 Newton matrix is not positive definite"
            << (external_kinetic_[b] ? " (external_kinetic = 1 and no energy term holds it)" : "");
        break;
      case kNonFinite:
        msg << "the Newton direction is not finite";
        break;
      case kLineSearch:
        msg << "the line search found no decrease of Π in " << settings_.max_line_search_iterations
            << " halvings";
        break;
      default:
        msg << "no convergence in " << r.iterations << " iterations";
    }
    msg << "; last step " << r.step_translation << " m/s, " << r.step_affine
        << " 1/s (tolerances " << settings_.tol_translation << ", " << settings_.tol_affine
        << "), residual " << r.residual;
    throw SolverError(msg.str());
  }

  d.converged = true;
  double kinetic = 0.0, shape = 0.0;
  for (int b = 0; b < n_; ++b) {
    const BodyNewton& r = result[b];
    d.newton_iterations = std::max(d.newton_iterations, r.iterations);
    d.total_body_iterations += r.iterations;
    d.step_translation = std::max(d.step_translation, r.step_translation);
    d.step_affine = std::max(d.step_affine, r.step_affine);
    d.residual = std::max(d.residual, r.residual);
    kinetic += r.kinetic;
    shape += r.shape;
  }
  for (int it = 0; it < d.newton_iterations; ++it) {
    double a = 2.0;
    for (const auto& t : alphas) a = std::min(a, t[it]);
    d.line_search_alphas.push_back(a <= 1.0 ? a : 1.0);
  }
  if (settings_.energies)
    d.energies = {{"kinetic", kinetic}, {"shape", shape}, {"total", kinetic + c2 * shape}};
}

}  // namespace abd
