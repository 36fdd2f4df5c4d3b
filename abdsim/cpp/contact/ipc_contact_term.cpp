// IpcContactTerm: construction, active sets, barrier + friction energy and derivatives.
// CCD, distances and feasibility checks are in ipc_contact_feasibility.cpp.
#include "contact/ipc_contact_term.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "contact/body_mapping.h"
#include "contact/parallel.h"

namespace abd {
namespace {
// Gap (fraction of d̂) below which a compressed pair's κ may still be raised (see update()).
constexpr double kCompressedGapFraction = 1e-2;
// How far (in d̂) vertices may move before the broad phase's candidates are queried again.
constexpr double kVerletSlack = 2.0;
}  // namespace
using namespace contact;

namespace {

const ContactSettings& validated(const ContactSettings& s) {
  if (!(s.d_hat > 0.0)) throw std::invalid_argument("ContactSettings: d_hat must be > 0");
  if (!(s.eps_v > 0.0)) throw std::invalid_argument("ContactSettings: eps_v must be > 0");
  if (!(s.mu >= 0.0)) throw std::invalid_argument("ContactSettings: mu must be >= 0");
  if (!(s.damping >= 0.0) || !std::isfinite(s.damping))
    throw std::invalid_argument("ContactSettings: damping must be finite and >= 0");
  if (!std::isfinite(s.restitution) || s.restitution > 1.0)
    throw std::invalid_argument("ContactSettings: restitution must be in [0, 1] (< 0: none)");
  if (!(s.restitution_threshold >= 0.0) || !std::isfinite(s.restitution_threshold))
    throw std::invalid_argument("ContactSettings: restitution_threshold must be finite and >= 0");
  if (!(s.ccd_target > 0.0 && s.ccd_target < 1.0))
    throw std::invalid_argument("ContactSettings: ccd_target must lie in (0, 1)");
  return s;
}

VecX stacked_q(const SceneData& scene) {
  VecX q(12 * scene.bodies.size());
  for (size_t b = 0; b < scene.bodies.size(); ++b) q.segment<12>(12 * b) = scene.bodies[b].q;
  return q;
}

// Evaluates eval(i) for i in [0, n) in chunks (in parallel when `parallel` and the chunk is
// big enough), then hands each result to consume(i, r) serially and in order: bounded memory,
// deterministic sums.
template <class Eval, class Consume>
void evaluate_in_order(int n, bool parallel, int threads, const Eval& eval,
                       const Consume& consume) {
  constexpr int kChunk = 4096;
  // Reused between calls: a StencilEnergy holds a 12x12 matrix, too big to construct afresh
  // for every stencil of every evaluation.
  thread_local std::vector<StencilEnergy> buffer;
  std::vector<StencilEnergy>& results = buffer;  // the calling thread's, also in the workers
  for (int begin = 0; begin < n; begin += kChunk) {
    const int end = std::min(n, begin + kChunk);
    if (results.size() < size_t(end - begin)) results.resize(size_t(end - begin));
    for_each_stencil(end - begin, parallel && end - begin >= kMinParallelHessians, threads,
                     [&](int k) { results[size_t(k)] = eval(begin + k); });
    for (int i = begin; i < end; ++i) consume(i, results[size_t(i - begin)]);
  }
}

}  // namespace

IpcContactTerm::IpcContactTerm(const SceneData& scene, const ContactSettings& settings)
    : settings_(validated(settings)),
      mesh_(ContactMesh::from_scene(scene)),
      table_(mesh_.num_bodies(), settings.body_contact_element, settings.ground_contact_element,
             settings.mu, settings.contact_table, settings.damping, settings.restitution),
      broad_phase_(mesh_, [this](int a, int b) { return bodies_may_collide(a, b); }),
      verlet_(settings_.d_hat, kVerletSlack * settings_.d_hat),
      scripted_(size_t(mesh_.num_bodies()), 0),
      threads_(resolve_threads(0)),
      dt_(scene.dt) {
  if (!(dt_ > 0.0)) throw std::invalid_argument("IpcContactTerm: scene dt must be > 0");
  settings_.contact_table = nullptr;  // resolved into table_; keep no reference to the rule
  const std::vector<Vec3> x = mesh_.world_vertices(stacked_q(scene));
  if (!x.empty()) {
    Vec3 lo = x[0], hi = x[0];
    for (const Vec3& p : x) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    bbox_diagonal_ = (hi - lo).norm();
  }
  if (!(bbox_diagonal_ > 0.0)) bbox_diagonal_ = 1.0;
  double mass_sum = 0.0;
  int n_dynamic = 0;
  for (int b = 0; b < mesh_.num_bodies(); ++b)
    if (!mesh_.fixed[b] && mesh_.mass[b] > 0.0) {
      mass_sum += mesh_.mass[b];
      ++n_dynamic;
    }
  average_mass_ = n_dynamic ? mass_sum / n_dynamic : 1.0;
  if (adaptive_kappa()) {
    kappa_min_ = min_barrier_stiffness(stiffness_length(), settings_.d_hat, average_mass_, dt_);
    kappa_max_ = 100.0 * kappa_min_;
    kappa_ = kappa_min_;
  } else {
    kappa_ = kappa_min_ = kappa_max_ = settings_.kappa;
  }
  friction_eps_ = settings_.eps_v * dt_;
  prev_min_gap_ = std::numeric_limits<double>::infinity();
  const size_t primitives = mesh_.rest.size() + mesh_.edges.size() + mesh_.faces.size();
  max_candidates_ = std::max(max_candidates_, 2 * primitives);
}

bool IpcContactTerm::bodies_may_collide(int a, int b) const {
  const bool passive_a = mesh_.fixed[a] || scripted_[a];
  if (b < 0) return settings_.ground && !passive_a && table_.ground(a).enabled;
  // Neither moves by the dynamics: nothing to resolve.
  if (passive_a && (mesh_.fixed[b] || scripted_[b])) return false;
  return table_.bodies(a, b).enabled;
}

void IpcContactTerm::set_threads(int threads) { threads_ = resolve_threads(threads); }

void IpcContactTerm::set_scripted(int body, bool scripted) {
  scripted_.at(body) = scripted;
  swept_.valid = false;  // the filter of the kept candidates changed
  verlet_.invalidate();
}

BarrierParams IpcContactTerm::barrier_params(double kappa) const {
  BarrierParams p;
  p.d_hat = settings_.d_hat;
  p.kappa = kappa;
  p.ground_height = settings_.ground_height;
  p.project_psd = settings_.project_hessian;
  return p;
}

ActiveSet IpcContactTerm::build_active_set(const VecX& q, double reach) const {
  std::vector<Vec3> x;
  const std::vector<Vec3>& known = vertices_at(q, x);
  if (&known != &x) x = known;
  BroadPhaseQuery query;
  query.margin = reach;
  query.ground = settings_.ground;
  query.ground_height = settings_.ground_height;
  if (reach == settings_.d_hat && on_swept_path(q, trial_times_)) {
    // Only the candidates whose gap bound along the path reaches below d̂ at these times
    // (swept_reach.h): the same active set as from all of them, far fewer distances.
    reachable_candidates(swept_.candidates, swept_.reach, trial_times_, reach, trial_candidates_);
    ActiveSet set = select_active(mesh_, table_, trial_candidates_, q, std::move(x), reach,
                                  settings_.ground_height);
#ifndef NDEBUG
    const ActiveSet full = select_active(mesh_, table_, swept_.candidates, q, set.x, reach,
                                         settings_.ground_height);
    assert(full.stencils.size() == set.stencils.size() && full.min_gap == set.min_gap);
#endif
    return set;
  }
  const Candidates candidates = bounded_query(x, query);
  return select_active(mesh_, table_, candidates, q, std::move(x), reach, settings_.ground_height);
}

const ActiveSet& IpcContactTerm::active_set_at(const VecX& q, ActiveSet& /*scratch*/) const {
  if (active_.q.size() == q.size() && active_.q == q) return active_;
  if (last_built_.q.size() != q.size() || last_built_.q != q)
    last_built_ = build_active_set(q, settings_.d_hat);
  return last_built_;
}

const std::vector<Vec3>& IpcContactTerm::vertices_at(const VecX& q,
                                                     std::vector<Vec3>& scratch) const {
  const ActiveSet* known[] = {&active_, &last_built_};
  for (const ActiveSet* s : known)
    if (s->q.size() == q.size() && s->x.size() == mesh_.rest.size() && s->q == q) return s->x;
  if (sweep_end_q_.size() == q.size() && sweep_end_.size() == mesh_.rest.size() && sweep_end_q_ == q)
    return sweep_end_;
  mesh_.world_vertices_into(q, scratch);
  return scratch;
}

std::array<int, 2> IpcContactTerm::stencil_bodies(const std::array<int, 4>& v, int nv) const {
  return {mesh_.vertex_body[v[0]], nv > 1 ? mesh_.vertex_body[v[nv - 1]] : -1};
}

void IpcContactTerm::set_kappa(double kappa) {
  if (!(kappa > 0.0)) throw std::invalid_argument("set_kappa: kappa must be > 0");
  kappa_ = kappa;
}

void IpcContactTerm::begin_step(const StepContext& ctx) {
  if (!(ctx.dt > 0.0)) throw std::invalid_argument("begin_step: dt must be > 0");
  dt_ = ctx.dt;
  swept_.valid = false;  // a new step: the kept candidates are the last step's
  potential_scale_ = ctx.potential_scale > 0.0 ? ctx.potential_scale : dt_ * dt_;
  // Friction smooths the sliding velocity (x − x_ref)/c below ε_v: a displacement of ε_v c.
  friction_eps_ = settings_.eps_v * std::sqrt(potential_scale_);
  if (active_.q.size() == ctx.q_t.size() && active_.q == ctx.q_t) {
    // the set of the last update (the previous step's end): still valid
  } else if (last_built_.q.size() == ctx.q_t.size() && last_built_.q == ctx.q_t) {
    active_ = last_built_;
  } else {
    active_ = build_active_set(ctx.q_t, settings_.d_hat);
    // A state the last step did not end in (the first step, or set_state): κ is chosen
    // afresh for it (the solver says so; a caller that does not is judged by the set).
    if (!ctx.fresh_state.has_value()) fresh_compressed_ = !active_.stencils.empty();
  }
  if (ctx.fresh_state.has_value()) fresh_compressed_ = *ctx.fresh_state && !active_.stencils.empty();
  // κ may only change while no pair is inside d̂ at the step start: the barrier's energy
  // at q_t is κ Σ b > 0 otherwise, and a stiffer κ would add energy to a compressed pair
  // out of nothing (a body resting inside d̂ leapt centimetres).
  compressed_at_start_ = !active_.stencils.empty();
  if (adaptive_kappa() && !compressed_at_start_) kappa_ = std::clamp(kappa_, kappa_min_, kappa_max_);
  const bool own_ref = ctx.q_ref && ctx.q_ref->size() == ctx.q_t.size() && *ctx.q_ref != ctx.q_t;
  friction_ref_ = own_ref ? mesh_.world_vertices(*ctx.q_ref) : active_.x;
  lag_dissipation();
}

std::vector<double> IpcContactTerm::inverse_masses() const {
  std::vector<double> inv(size_t(mesh_.num_bodies()), 0.0);
  for (int b = 0; b < mesh_.num_bodies(); ++b)
    if (!mesh_.fixed[b] && !scripted_[b] && mesh_.mass[b] > 0.0) inv[size_t(b)] = 1.0 / mesh_.mass[b];
  return inv;
}

void IpcContactTerm::lag_dissipation() {
  friction_ = lag_friction(active_, friction_ref_, barrier_params(kappa_));
  damping_ = lag_damping(active_, friction_ref_, barrier_params(kappa_), inverse_masses());
}

bool IpcContactTerm::refresh_lagged(const VecX& q) {
  if (active_.q.size() != q.size() || active_.q != q) update(q);
  std::vector<FrictionStencil> fresh = lag_friction(active_, friction_ref_, barrier_params(kappa_));
  if (same_friction(fresh, friction_)) return false;  // the solution stands
  friction_ = std::move(fresh);
  return true;
}

void IpcContactTerm::update(const VecX& q) {
  if (last_built_.q.size() == q.size() && last_built_.q == q) {
    active_ = std::move(last_built_);
    last_built_ = ActiveSet();
  } else if (active_.q.size() != q.size() || active_.q != q) {
    active_ = build_active_set(q, settings_.d_hat);
  }
  if (adaptive_kappa()) {
    // IPC: if the closest gap is tiny and still shrinking, the barrier is too soft. While
    // pairs were compressed at the step start, a stiffer κ adds energy to them, so it
    // only happens as a last resort, once a gap has shrunk below 1e-2 d̂ (a load far above
    // the one κ was chosen for, e.g. a kinematic grasp on a body resting on the ground).
    const double eps_scale =
        compressed_at_start_ ? kCompressedGapFraction * settings_.d_hat / bbox_diagonal_ : 1e-9;
    kappa_ = update_barrier_stiffness(prev_min_gap_, active_.min_gap, kappa_max_, kappa_,
                                      bbox_diagonal_, eps_scale);
    prev_min_gap_ = active_.min_gap;
  }
}

void IpcContactTerm::set_no_active_pairs(const VecX& q) {
  active_ = ActiveSet();
  active_.q = q;
  active_.x = mesh_.world_vertices(q);
  prev_min_gap_ = active_.min_gap;
}

double IpcContactTerm::initialize_kappa(const VecX& q, const VecX& grad_rest) {
  if (!adaptive_kappa()) return kappa_;
  if (grad_rest.size() != q.size())
    throw std::invalid_argument("initialize_kappa: grad_rest must have the size of q");
  ActiveSet scratch;
  const ActiveSet& set = active_set_at(q, scratch);
  VecX grad_barrier = VecX::Zero(q.size());
  add_barrier_gradient(set, 1.0, 1.0, grad_barrier);
  VecX rest = grad_rest;
  for (int b = 0; b < mesh_.num_bodies(); ++b) {
    if (mesh_.fixed[b]) {  // fixed dofs balance nothing
      grad_barrier.segment<12>(12 * b).setZero();
      rest.segment<12>(12 * b).setZero();
    }
    // Only the translations: the barrier's moments on A are held by the stiff shape
    // energy, not by the load, and counting them biased κ low (a box placed inside d̂ did
    // not quite start in equilibrium). This is IPC's vertex-space balance for ABD's dofs.
    grad_barrier.segment<9>(12 * b + 3).setZero();
    rest.segment<9>(12 * b + 3).setZero();
  }
  if (compressed_at_start_ && !fresh_compressed_) return kappa_;  // energy-neutral: keep it
  const double h = potential_scale_ > 0.0 ? std::sqrt(potential_scale_) : dt_;
  // The barrier's share of ∇Π is c² κ ∇b: the balance against the rest (IPC) is in
  // units of c², so it uses this step's c.
  const double balance = balanced_barrier_stiffness(h, rest, grad_barrier);
  if (compressed_at_start_) {
    fresh_compressed_ = false;
    // Pairs already inside d̂ at a fresh state (bodies loaded resting on each other):
    // the balance makes that state an equilibrium. κ_min would store far more than the
    // load's energy in the barrier, released as a jump.
    if (balance > 0.0) kappa_ = std::min(balance, kappa_max_);
    // Friction and damping were lagged with the old κ: they follow the barrier's.
    lag_dissipation();
    return kappa_;
  }
  kappa_ = balance > 0.0 ? std::clamp(balance, kappa_min_, kappa_max_) : kappa_min_;
  return kappa_;
}

double IpcContactTerm::barrier_value(const VecX& q) const {
  ActiveSet scratch;
  const ActiveSet& set = active_set_at(q, scratch);
  if (set.infeasible >= 0) return std::numeric_limits<double>::infinity();
  const BarrierParams p = barrier_params(kappa_);
  double sum = 0.0;
  for (size_t i = 0; i < set.stencils.size(); ++i)
    sum += stencil_barrier_value(set.stencils[i], set.distances[i], set.x, p);
  return sum;
}

double IpcContactTerm::friction_value(const VecX& q) const {
  if (friction_.empty()) return 0.0;
  std::vector<Vec3> scratch;
  const std::vector<Vec3>& x = vertices_at(q, scratch);
  double sum = 0.0;
  for (const FrictionStencil& f : friction_) sum += friction_energy(f, x, friction_eps_, 0).value;
  return sum;
}

double IpcContactTerm::damping_value(const VecX& q) const {
  if (damping_.empty()) return 0.0;
  std::vector<Vec3> scratch;
  const std::vector<Vec3>& x = vertices_at(q, scratch);
  double sum = 0.0;
  for (const DampingStencil& d : damping_) sum += damping_energy(d, x, step_scale(), 0).value;
  return sum;
}

double IpcContactTerm::value(const VecX& q) const {
  return barrier_value(q) + friction_value(q) + damping_value(q);
}

void IpcContactTerm::add_barrier_gradient(const ActiveSet& set, double kappa, double scale,
                                          VecX& gradient) const {
  const BarrierParams p = barrier_params(kappa);
  evaluate_in_order(
      int(set.stencils.size()), false, threads_,
      [&](int i) { return stencil_barrier(set.stencils[i], set.x, p, 1); },
      [&](int i, const StencilEnergy& e) {
        const ContactStencil& s = set.stencils[i];
        add_stencil_gradient(mesh_, s.vertices, s.nv, e.grad, scale, gradient);
      });
}

void IpcContactTerm::add_gradient(const VecX& q, double scale, VecX& gradient) const {
  if (gradient.size() != q.size())
    throw std::invalid_argument("add_gradient: gradient must have the size of q");
  ActiveSet scratch;
  const ActiveSet& set = active_set_at(q, scratch);
  add_barrier_gradient(set, kappa_, scale, gradient);
  evaluate_in_order(
      int(friction_.size()), false, threads_,
      [&](int i) { return friction_energy(friction_[i], set.x, friction_eps_, 1); },
      [&](int i, const StencilEnergy& e) {
        add_stencil_gradient(mesh_, friction_[i].vertices, friction_[i].nv, e.grad, scale, gradient);
      });
  evaluate_in_order(
      int(damping_.size()), false, threads_,
      [&](int i) { return damping_energy(damping_[i], set.x, step_scale(), 1); },
      [&](int i, const StencilEnergy& e) {
        add_stencil_gradient(mesh_, damping_[i].vertices, damping_[i].nv, e.grad, scale, gradient);
      });
}

void IpcContactTerm::add_hessian(const VecX& q, double scale, std::vector<BodyBlock>& blocks) const {
  add_derivatives(q, scale, nullptr, blocks);
}

void IpcContactTerm::add_gradient_and_hessian(const VecX& q, double scale, VecX& gradient,
                                              std::vector<BodyBlock>& blocks) const {
  if (gradient.size() != q.size())
    throw std::invalid_argument("add_gradient_and_hessian: gradient must have the size of q");
  add_derivatives(q, scale, &gradient, blocks);
}

// One pass per stencil for the Hessian and (if asked) the gradient.
void IpcContactTerm::add_derivatives(const VecX& q, double scale, VecX* gradient,
                                     std::vector<BodyBlock>& blocks) const {
  ActiveSet scratch;
  const ActiveSet& set = active_set_at(q, scratch);
  const BarrierParams p = barrier_params(kappa_);
  BodyBlockAccumulator& acc = block_accumulator_;
  acc.clear();  // a throw left part of an evaluation in it
  evaluate_in_order(
      int(set.stencils.size()), true, threads_,
      [&](int i) { return stencil_barrier(set.stencils[i], set.x, p, 2); },
      [&](int i, const StencilEnergy& e) {
        const ContactStencil& s = set.stencils[i];
        if (gradient) add_stencil_gradient(mesh_, s.vertices, s.nv, e.grad, scale, *gradient);
        acc.add_stencil(mesh_, s.vertices, s.nv, e.hess, scale);
      });
  evaluate_in_order(
      int(friction_.size()), false, threads_,
      [&](int i) {
        return friction_energy(friction_[i], set.x, friction_eps_, 2, majorize_friction_);
      },
      [&](int i, const StencilEnergy& e) {
        const FrictionStencil& f = friction_[i];
        if (gradient) add_stencil_gradient(mesh_, f.vertices, f.nv, e.grad, scale, *gradient);
        acc.add_stencil(mesh_, f.vertices, f.nv, e.hess, scale);
      });
  evaluate_in_order(
      int(damping_.size()), false, threads_,
      [&](int i) { return damping_energy(damping_[i], set.x, step_scale(), 2); },
      [&](int i, const StencilEnergy& e) {
        const DampingStencil& d = damping_[i];
        if (gradient) add_stencil_gradient(mesh_, d.vertices, d.nv, e.grad, scale, *gradient);
        acc.add_stencil(mesh_, d.vertices, d.nv, e.hess, scale);
      });
  acc.flush_into(blocks);
}

ContactCounts IpcContactTerm::counts() const {
  ContactCounts c;
  for (const ContactStencil& s : active_.stencils) {
    if (s.kind == StencilKind::PointTriangle) ++c.point_triangle;
    if (s.kind == StencilKind::EdgeEdge) ++c.edge_edge;
    if (s.kind == StencilKind::PointGround) ++c.point_ground;
  }
  c.friction = int(friction_.size());
  c.damping = int(damping_.size());
  return c;
}

}  // namespace abd

namespace abd {

void IpcContactTerm::add_body_values(const VecX& q, const std::vector<unsigned char>& movable,
                                     VecX& per_body, std::vector<BodyLink>& links) const {
  if (per_body.size() != mesh_.num_bodies() || int(movable.size()) != mesh_.num_bodies())
    throw std::invalid_argument("add_body_values: per_body and movable need one entry per body");
  ActiveSet scratch;
  const ActiveSet& set = active_set_at(q, scratch);
  auto owner = [&](const std::array<int, 2>& b) {
    if (movable[b[0]]) return b[0];
    return b[1] >= 0 && movable[b[1]] ? b[1] : -1;
  };
  auto link = [&](const std::array<int, 2>& b) {
    if (b[1] >= 0 && b[0] != b[1] && movable[b[0]] && movable[b[1]]) links.push_back({b[0], b[1]});
  };
  const BarrierParams p = barrier_params(kappa_);
  for (size_t i = 0; i < set.stencils.size(); ++i) {
    const ContactStencil& s = set.stencils[i];
    const std::array<int, 2> b{s.bodies[0], s.bodies[1]};
    const int o = owner(b);
    link(b);
    if (o >= 0) per_body[o] += stencil_barrier_value(s, set.distances[i], set.x, p);
  }
  for (const FrictionStencil& f : friction_) {
    const std::array<int, 2> b = stencil_bodies(f.vertices, f.nv);
    const int o = owner(b);
    link(b);
    if (o >= 0) per_body[o] += friction_energy(f, set.x, friction_eps_, 0).value;
  }
  for (const DampingStencil& d : damping_) {
    const std::array<int, 2> b = stencil_bodies(d.vertices, d.nv);
    const int o = owner(b);
    link(b);
    if (o >= 0) per_body[o] += damping_energy(d, set.x, step_scale(), 0).value;
  }
}

void IpcContactTerm::mark_friction_bodies(std::vector<unsigned char>& flags) const {
  for (const FrictionStencil& f : friction_)
    for (int b : stencil_bodies(f.vertices, f.nv))
      if (b >= 0 && b < int(flags.size())) flags[size_t(b)] = 1;
  for (const DampingStencil& d : damping_)
    for (int b : stencil_bodies(d.vertices, d.nv))
      if (b >= 0 && b < int(flags.size())) flags[size_t(b)] = 1;
}

void IpcContactTerm::mark_active_bodies(std::vector<unsigned char>& flags) const {
  for (const ContactStencil& s : active_.stencils)
    for (int b : s.bodies)
      if (b >= 0 && b < int(flags.size())) flags[size_t(b)] = 1;
}

void IpcContactTerm::body_links(const std::vector<unsigned char>& movable,
                                std::vector<BodyLink>& links) const {
  auto link = [&](const std::array<int, 2>& b) {
    if (b[1] >= 0 && b[0] != b[1] && movable[b[0]] && movable[b[1]]) links.push_back({b[0], b[1]});
  };
  for (const ContactStencil& s : active_.stencils) link({s.bodies[0], s.bodies[1]});
  for (const FrictionStencil& f : friction_) link(stencil_bodies(f.vertices, f.nv));
  for (const DampingStencil& d : damping_) link(stencil_bodies(d.vertices, d.nv));
}

}  // namespace abd
