#include "joints/joint_force_term.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/psd.h"
#include "joints/joint_limit_coordinate.h"
#include "joints/joint_potentials.h"
#include "joints/joint_state.h"

namespace abd {
namespace {

bool acts(const JointPhysics& p) {
  return p.stiffness != 0.0 || p.damping != 0.0 || p.armature != 0.0 || p.frictionloss != 0.0 ||
         p.limited;
}

// Effective inertia of the child about the hinge axis through the anchor (revolute) or its
// mass (prismatic), from its dyadic mass in rest coordinates.
double child_inertia(const JointFrame& f, const SceneData& scene, const VecX& q0) {
  const BodyData& b = scene.bodies[f.spec.child];
  if (f.spec.kind == JointKind::kPrismatic) return b.mass;
  const Vec3 a = f.anchor_c;
  const Mat3 S = b.mass_x_bar_x_bar - b.mass_x_bar * a.transpose() - a * b.mass_x_bar.transpose() +
                 b.mass * a * a.transpose();
  const Mat3 I = S.trace() * Mat3::Identity() - S;
  const Vec3 t = (nearest_rotation(affine_A(q0.segment<12>(12 * f.spec.child))).transpose() *
                  f.spec.axis).normalized();
  return std::max(t.dot(I * t), 1e-12);
}

}  // namespace

JointForceTerm::JointForceTerm(std::shared_ptr<const JointSet> joints, const SceneData& scene,
                               const std::vector<JointPhysics>& physics,
                               const std::vector<ActuatorSpec>& actuators)
    : joints_(std::move(joints)), physics_(physics), actuators_(actuators) {
  if (!joints_) throw std::invalid_argument("JointForceTerm: no joints");
  const int nj = joints_->size();
  if (static_cast<int>(physics_.size()) != nj)
    throw std::invalid_argument("JointForceTerm: one JointPhysics per joint");
  VecX q0(12 * scene.bodies.size());
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) q0.segment<12>(12 * b) = scene.bodies[b].q;
  std::vector<unsigned char> driven(nj, 0);
  for (const ActuatorSpec& a : actuators_) {
    if (a.joint < 0 || a.joint >= nj) throw std::invalid_argument("actuator joint out of range");
    driven[a.joint] = 1;
  }
  element_of_joint_.assign(nj, -1);
  for (int j = 0; j < nj; ++j) {
    const JointFrame& f = joints_->frame(j);
    const bool one_dof = f.spec.kind == JointKind::kRevolute || f.spec.kind == JointKind::kPrismatic;
    const std::string who = "joint '" + f.spec.name + "'";
    if (!one_dof && (acts(physics_[j]) || driven[j]))
      throw std::invalid_argument(who + ": joint physics and actuators act on revolute and "
                                  "prismatic joints only");
    const JointPhysics& p = physics_[j];
    if (p.limited && !(p.lower < 0.0 && 0.0 < p.upper))
      throw std::invalid_argument(who + ": the configuration at load (coordinate 0) must lie "
                                  "strictly inside the limits (" + std::to_string(p.lower) +
                                  ", " + std::to_string(p.upper) + ")");
    if (!one_dof) continue;
    element_of_joint_[j] = static_cast<int>(elements_.size());
    Element e;
    e.joint = j;
    e.inertia = child_inertia(f, scene, q0) + p.armature;
    elements_.push_back(e);
  }
  // Each element's actuators, in actuator order (energy() visits them per element, every
  // evaluation: a scan of all actuators per element was quadratic in the joints).
  actuators_of_.assign(elements_.size(), {});
  for (std::size_t a = 0; a < actuators_.size(); ++a)
    actuators_of_[static_cast<std::size_t>(element_of_joint_[actuators_[a].joint])].push_back(
        static_cast<int>(a));
  ctrl_ = VecX::Zero(static_cast<Eigen::Index>(actuators_.size()));
  tau_ = VecX::Zero(nj);
  act_F0_.assign(actuators_.size(), 0.0);
  act_F1_.assign(actuators_.size(), 0.0);
}

void JointForceTerm::set_joint_forces(const VecX& tau) {
  if (tau.size() != tau_.size())
    throw std::invalid_argument("set_joint_forces: one value per joint (" +
                                std::to_string(tau_.size()) + ")");
  if (!tau.allFinite()) throw std::invalid_argument("set_joint_forces: forces must be finite");
  for (int j = 0; j < tau.size(); ++j)
    if (tau[j] != 0.0 && element_of_joint_[j] < 0)
      throw std::invalid_argument("set_joint_forces: joint '" + joints_->frame(j).spec.name +
                                  "' takes no generalized force (not a 1-dof joint)");
  tau_ = tau;
}

double JointForceTerm::theta_of(const Element& e, const VecX& q, Vec12* gc, Vec12* gp) const {
  double theta = joints_->coordinate(e.joint, q, gc, gp);  // cached per state (JointSet)
  if (joints_->frame(e.joint).spec.kind == JointKind::kRevolute) {  // unwrap against the step start
    const double two_pi = 2.0 * M_PI;
    theta += two_pi * std::round((e.theta_t - theta) / two_pi);
  }
  return theta;
}

void JointForceTerm::begin_step(const StepContext& ctx) {
  const double h = ctx.dt;
  c_ = std::sqrt(ctx.potential_scale);
  const bool bdf2 = c_ < 0.99 * h;
  // θ at the step start: hinge angles unwrapped as joint positions read them (the last
  // end_step's, at its state: a step begins where the last one ended); a slide's coordinate
  // needs no unwrapping (theta_of reads it as it is, whatever theta_t holds).
  const bool at_last_end = joints_->at_last_end_step(ctx.q_t);
  const VecX angles = at_last_end ? VecX() : joints_->positions(ctx.q_t);
  for (Element& e : elements_) {
    const JointFrame& f = joints_->frame(e.joint);
    Vec12 gc, gp;
    if (f.spec.kind == JointKind::kRevolute)
      e.theta_t = at_last_end ? joints_->last_angle(e.joint)
                              : angles[joints_->q_offset(e.joint)];
    const double theta = theta_of(e, ctx.q_t, &gc, &gp);
    double rate = gc.dot(ctx.q_dot_t.segment<12>(12 * f.spec.child));
    if (f.spec.parent >= 0) rate += gp.dot(ctx.q_dot_t.segment<12>(12 * f.spec.parent));
    // History shifts once per step: a step begun again from the same start (after a failed
    // attempt) keeps the previous one.
    if (e.has_start && (theta != e.start_theta || rate != e.start_rate)) {
      e.prev_theta = e.start_theta;
      e.prev_rate = e.start_rate;
      e.has_prev = true;
    }
    e.start_theta = theta;
    e.start_rate = rate;
    e.has_start = true;
    if (bdf2 && e.has_prev) {
      e.theta_hat = (4.0 * theta - e.prev_theta) / 3.0;
      e.theta_tilde = e.theta_hat + c_ * (4.0 * rate - e.prev_rate) / 3.0;
    } else {
      e.theta_hat = theta;
      e.theta_tilde = theta + c_ * rate;
    }
    e.theta_t = theta;
    // Barrier stiffness on the scale of the joint's kinetic term: κ d̂² ~ I (d̂/c)².
    e.kappa = e.inertia / (c_ * c_);
    e.at_limit_start = e.at_limit = at_limit(e, theta);
  }
  // Actuator force = gain·u + b0 + b1·L + b2·L̇ with L = gear θ, L̇ = gear (θ − θ̂)/c (MuJoCo's
  // general actuator with the motor / position / velocity presets), as F0 + F1 θ.
  for (std::size_t a = 0; a < actuators_.size(); ++a) {
    const ActuatorSpec& s = actuators_[a];
    double u = ctrl_[static_cast<Eigen::Index>(a)];
    if (s.ctrl_limited) u = std::clamp(u, s.ctrl_lower, s.ctrl_upper);
    double gain = 1.0, b1 = 0.0, b2 = 0.0;
    if (s.kind == ActuatorKind::kPosition) {
      gain = s.kp;
      b1 = -s.kp;
      b2 = -s.kv;
    } else if (s.kind == ActuatorKind::kVelocity) {
      gain = s.kv;
      b2 = -s.kv;
    }
    const int el = element_of_joint_[s.joint];
    const double theta_hat = elements_[el].theta_hat;
    act_F0_[a] = gain * u + s.bias - b2 * s.gear * theta_hat / c_;
    act_F1_[a] = s.gear * (b1 + b2 / c_);
  }
}

bool JointForceTerm::at_limit(const Element& e, double theta) const {
  const JointPhysics& p = physics_[e.joint];
  return p.limited && (theta - p.lower < kLimitMargin || p.upper - theta < kLimitMargin);
}

void JointForceTerm::update(const VecX& q) {
  for (Element& e : elements_)
    if (physics_[e.joint].limited) e.at_limit = at_limit(e, theta_of(e, q, nullptr, nullptr));
}

bool JointForceTerm::broke_smoothness() const {
  for (const Element& e : elements_)
    if (e.at_limit != e.at_limit_start) return true;
  return false;
}

bool JointForceTerm::energy(const Element& e, double theta, double& E, double& d1,
                            double& d2, double* limit_d1) const {
  const JointPhysics& p = physics_[e.joint];
  Scalar1D s;
  if (p.stiffness != 0.0) add_quadratic(s, p.stiffness, theta, p.ref);
  if (p.damping != 0.0) add_quadratic(s, p.damping / c_, theta, e.theta_hat);
  if (p.armature != 0.0) add_quadratic(s, p.armature / (c_ * c_), theta, e.theta_tilde);
  if (p.frictionloss != 0.0)
    add_dry_friction(s, p.frictionloss, theta, e.theta_hat, c_, kFrictionSpeed);
  if (tau_[e.joint] != 0.0) add_linear_force(s, tau_[e.joint], theta);
  if (limit_d1) *limit_d1 = 0.0;
  if (p.limited) {
    Scalar1D barrier;
    if (!add_limit_barrier(barrier, theta, p.lower, +1, kLimitMargin, e.kappa)) return false;
    if (!add_limit_barrier(barrier, theta, p.upper, -1, kLimitMargin, e.kappa)) return false;
    s.e += barrier.e;
    s.d1 += barrier.d1;
    s.d2 += barrier.d2;
    if (limit_d1) *limit_d1 = barrier.d1;
  }
  for (const int a : actuators_of_[static_cast<std::size_t>(&e - elements_.data())]) {
    const ActuatorSpec& spec = actuators_[a];
    const double inf = std::numeric_limits<double>::infinity();
    add_clamped_actuator(s, theta, spec.gear, act_F0_[a], act_F1_[a],
                         spec.force_limited ? spec.force_lower : -inf,
                         spec.force_limited ? spec.force_upper : inf);
  }
  E = s.e;
  d1 = s.d1;
  d2 = s.d2;
  return true;
}

double JointForceTerm::value(const VecX& q) const {
  double total = 0.0;
  for (const Element& e : elements_) {
    double E, d1, d2;
    if (!energy(e, theta_of(e, q, nullptr, nullptr), E, d1, d2))
      return std::numeric_limits<double>::infinity();
    total += E;
  }
  return total;
}

void JointForceTerm::assemble(const VecX& q, double scale, VecX* gradient,
                              std::vector<BodyBlock>* blocks,
                              std::vector<HessianRow>* rows) const {
  for (const Element& e : elements_) {
    Vec12 gc, gp;
    double E, d1, d2, limit_d1;
    if (!energy(e, theta_of(e, q, &gc, &gp), E, d1, d2, &limit_d1)) continue;
    const JointFrame& f = joints_->frame(e.joint);
    const int c = f.spec.child, p = f.spec.parent;
    if (gradient) {
      gradient->segment<12>(12 * c) += scale * d1 * gc;
      if (p >= 0) gradient->segment<12>(12 * p) += scale * d1 * gp;
    }
    if (blocks && limit_d1 != 0.0) {
      // A barrier pushing: its force E'(θ) turns with θ's gradient as the bodies move, the
      // curvature term E' ∇²θ of the Hessian (Newton's exact second order at a limit; the
      // parent-frame angle alone already fixed tiago_pro's stall). Projected to PSD as one matrix
      // with the Gauss–Newton part (the sum is what Newton needs to be a descent direction).
      Mat24 H;
      joint_limit_coordinate(f, q, nullptr, nullptr, &H);
      Eigen::Matrix<double, 24, 1> g;
      g << gc, gp;
      H = scale * (limit_d1 * H + d2 * g * g.transpose());
      if (p < 0) {
        blocks->push_back({c, c, project_psd(H.topLeftCorner<12, 12>())});
        continue;
      }
      H = project_psd(H);
      blocks->push_back({c, c, H.topLeftCorner<12, 12>()});
      blocks->push_back({p, p, H.bottomRightCorner<12, 12>()});
      blocks->push_back({c, p, H.topRightCorner<12, 12>()});
      blocks->push_back({p, c, H.bottomLeftCorner<12, 12>()});
      continue;
    }
    if (!blocks || d2 == 0.0) continue;
    const double k = scale * d2;
    if (rows && p >= 0 && k > 0.0) {
      rows->push_back({c, p, gc, gp, k});
      continue;
    }
    blocks->push_back({c, c, k * gc * gc.transpose()});
    if (p < 0) continue;
    blocks->push_back({p, p, k * gp * gp.transpose()});
    blocks->push_back({c, p, k * gc * gp.transpose()});
    blocks->push_back({p, c, k * gp * gc.transpose()});
  }
}

void JointForceTerm::add_gradient(const VecX& q, double scale, VecX& gradient) const {
  assemble(q, scale, &gradient, nullptr, nullptr);
}

void JointForceTerm::add_hessian(const VecX& q, double scale,
                                 std::vector<BodyBlock>& blocks) const {
  assemble(q, scale, nullptr, &blocks, nullptr);
}

void JointForceTerm::add_gradient_and_hessian(const VecX& q, double scale, VecX& gradient,
                                              std::vector<BodyBlock>& blocks) const {
  assemble(q, scale, &gradient, &blocks, nullptr);
}

void JointForceTerm::add_gradient_and_hessian_rows(const VecX& q, double scale, VecX& gradient,
                                                   std::vector<BodyBlock>& blocks,
                                                   std::vector<HessianRow>& rows) const {
  assemble(q, scale, &gradient, &blocks, &rows);
}

// Largest α with the path q + t dq, t in [0, α], inside the limits: the coordinate is
// sampled along the path and the first crossing bisected.
double JointForceTerm::limit_step(const Element& e, const VecX& q, const VecX& dq) const {
  const JointPhysics& p = physics_[e.joint];
  if (!p.limited) return 1.0;
  auto inside = [&](double t) {
    const double theta = theta_of(e, q + t * dq, nullptr, nullptr);
    return theta > p.lower && theta < p.upper;
  };
  constexpr int kSamples = 8;
  double good = 0.0;
  for (int k = 1; k <= kSamples; ++k) {
    const double t = static_cast<double>(k) / kSamples;
    if (inside(t)) {
      good = t;
      continue;
    }
    double lo = good, hi = t;
    for (int it = 0; it < 40; ++it) {
      const double mid = 0.5 * (lo + hi);
      (inside(mid) ? lo : hi) = mid;
    }
    return lo;
  }
  return 1.0;
}

double JointForceTerm::max_step(const VecX& q, const VecX& dq) const {
  double alpha = 1.0;
  for (const Element& e : elements_) alpha = std::min(alpha, limit_step(e, q, dq));
  return alpha;
}

void JointForceTerm::limit_tolerances(VecX& tol_translation, VecX& tol_affine,
                                      const std::vector<double>& /*radius*/) const {
  const double tol = 0.1 * kFrictionSpeed;
  for (const Element& e : elements_) {
    if (physics_[e.joint].frictionloss == 0.0) continue;
    const JointFrame& f = joints_->frame(e.joint);
    for (int b : {f.spec.child, f.spec.parent}) {
      if (b < 0) continue;
      // A turn at ε rad/s moves points at most ε·lever (the lever: the child's size).
      tol_translation[b] = std::min(tol_translation[b], tol * std::min(f.lever, 1.0));
      tol_affine[b] = std::min(tol_affine[b], tol);
    }
  }
}

void JointForceTerm::add_body_values(const VecX& q, const std::vector<unsigned char>& movable,
                                     VecX& per_body, std::vector<BodyLink>& links) const {
  for (const Element& e : elements_) {
    const JointFrame& f = joints_->frame(e.joint);
    const int owner = movable[f.spec.child] ? f.spec.child
                      : (f.spec.parent >= 0 && movable[f.spec.parent]) ? f.spec.parent
                                                                         : -1;
    if (owner < 0) continue;
    double E, d1, d2;
    if (!energy(e, theta_of(e, q, nullptr, nullptr), E, d1, d2))
      E = std::numeric_limits<double>::infinity();
    per_body[owner] += E;
  }
  body_links(movable, links);
}

void JointForceTerm::body_links(const std::vector<unsigned char>& movable,
                                std::vector<BodyLink>& links) const {
  for (const Element& e : elements_) {
    const JointFrame& f = joints_->frame(e.joint);
    if (f.spec.parent >= 0 && movable[f.spec.parent] && movable[f.spec.child])
      links.push_back({f.spec.parent, f.spec.child});
  }
}

void JointForceTerm::mark_forced_bodies(std::vector<unsigned char>& flags) const {
  for (const Element& e : elements_) {
    const JointFrame& f = joints_->frame(e.joint);
    if (f.spec.parent >= 0) flags[size_t(f.spec.parent)] = 1;
    flags[size_t(f.spec.child)] = 1;
  }
}

void JointForceTerm::body_max_steps(const VecX& q, const VecX& dq,
                                    const std::vector<unsigned char>& movable, VecX& bound,
                                    std::vector<unsigned char>& near,
                                    std::vector<BodyLink>& links) const {
  for (const Element& e : elements_) {
    const JointFrame& f = joints_->frame(e.joint);
    const double alpha = limit_step(e, q, dq);
    for (int b : {f.spec.child, f.spec.parent}) {
      if (b < 0) continue;
      near[b] = 1;
      bound[b] = std::min(bound[b], alpha);
    }
  }
  body_links(movable, links);
}

}  // namespace abd
