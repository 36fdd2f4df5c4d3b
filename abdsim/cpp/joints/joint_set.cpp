#include "joints/joint_set.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "joints/joint_coordinates.h"
#include "joints/joint_frame.h"
#include "joints/joint_limit_coordinate.h"
#include "joints/joint_rows.h"
#include "joints/joint_state.h"

namespace abd {

JointSet::JointSet(const SceneData& scene, const VecX& q0, const std::vector<JointSpec>& specs) {
  const int n = static_cast<int>(scene.bodies.size());
  if (q0.size() != 12 * n)
    throw std::invalid_argument("joints: q0 must have 12 * n_bodies entries");
  std::vector<int> parent_of(n, -2);
  std::vector<int> root(n + 1);  // union-find over bodies and the world (index n)
  std::iota(root.begin(), root.end(), 0);
  auto find = [&](int b) {
    while (root[b] != b) b = root[b] = root[root[b]];
    return b;
  };
  for (const JointSpec& s : specs) {
    frames_.push_back(make_joint_frame(s, scene, q0));  // range and geometry checks
    const std::string who = "joint '" + s.name + "'";
    if (parent_of[s.child] != -2)
      throw std::invalid_argument(who + ": body " + std::to_string(s.child) +
                                  " is already the child of another joint (each body has "
                                  "one parent joint)");
    parent_of[s.child] = s.parent;
    const int a = find(s.child), b = find(s.parent < 0 ? n : s.parent);
    if (a == b)
      throw std::invalid_argument(who + ": it closes a kinematic loop (loops are not supported)");
    root[a] = b;
  }
  linear_rows_.resize(frames_.size());
  for (std::size_t j = 0; j < frames_.size(); ++j)
    if (joint_rows_linear(frames_[j])) append_joint_rows(frames_[j], q0, linear_rows_[j]);
  for (const JointFrame& f : frames_) {
    q_offset_.push_back(nq_);
    v_offset_.push_back(nv_);
    nq_ += joint_nq(f.spec.kind);
    nv_ += joint_nv(f.spec.kind);
    linear_ = linear_ && joint_rows_linear(f);
  }
  last_angle_.assign(frames_.size(), 0.0);
  coordinate_cache_.resize(frames_.size());
  reset(q0);
}

void JointSet::linearize(const VecX& q, std::vector<ConstraintRow>& rows) const {
  for (std::size_t j = 0; j < frames_.size(); ++j) {
    const std::vector<ConstraintRow>& fixed_gradients = linear_rows_[j];
    if (fixed_gradients.empty()) {
      append_joint_rows(frames_[j], q, rows);
      continue;
    }
    const std::size_t first = rows.size();
    rows.insert(rows.end(), fixed_gradients.begin(), fixed_gradients.end());
    set_joint_row_values(frames_[j], q, rows.data() + first);
  }
}

void JointSet::linearize_with_values(const VecX& q, const ConstraintValue* known,
                                     std::vector<ConstraintRow>& rows) const {
  for (std::size_t j = 0; j < frames_.size(); ++j) {
    const std::vector<ConstraintRow>& fixed_gradients = linear_rows_[j];
    const std::size_t first = rows.size();
    if (fixed_gradients.empty()) {
      append_joint_rows(frames_[j], q, rows);
    } else {
      rows.insert(rows.end(), fixed_gradients.begin(), fixed_gradients.end());
      for (std::size_t k = first; k < rows.size(); ++k) rows[k].value = known[k - first].value;
    }
    known += rows.size() - first;  // one value per row, in the rows' order
  }
}

void JointSet::values(const VecX& q, std::vector<ConstraintValue>& out) const {
  for (const JointFrame& f : frames_) append_joint_values(f, q, out);
}

void JointSet::nonlinear_values(const VecX& q, std::vector<ConstraintValue>& out) const {
  for (std::size_t j = 0; j < frames_.size(); ++j)
    if (linear_rows_[j].empty()) append_joint_values(frames_[j], q, out);
}

void JointSet::body_links(std::vector<BodyLink>& links) const {
  for (const JointFrame& f : frames_)
    if (f.spec.parent >= 0) links.push_back({f.spec.parent, f.spec.child});
}

void JointSet::mark_bodies(std::vector<unsigned char>& marked) const {
  for (const JointFrame& f : frames_) {
    if (f.spec.kind == JointKind::kFree) continue;
    marked[f.spec.child] = 1;
    if (f.spec.parent >= 0) marked[f.spec.parent] = 1;
  }
}

ConstraintViolation JointSet::violation(const VecX& q) const {
  WorstViolation worst;  // one square root and one atan2 for all joints
  for (const JointFrame& f : frames_) add_joint_violation(f, q, worst);
  return worst.result();
}

bool JointSet::cache_holds(int j, const VecX& q) const {
  const JointFrame& f = frames_[j];
  const CoordinateCache& cached = coordinate_cache_[j];
  // The world (body −1) is always the identity state: nothing to compare there.
  auto same = [&](const Vec12& state, int b) {
    return b < 0 || same_bits(state.data(), q.data() + 12 * b, 12);
  };
  return cached.valid && same(cached.qc, f.spec.child) && same(cached.qp, f.spec.parent);
}

double JointSet::coordinate(int j, const VecX& q, Vec12* grad_child, Vec12* grad_parent) const {
  const JointFrame& f = frames_[j];
  CoordinateCache& cached = coordinate_cache_[j];
  coordinates_read_ = true;
  if (!cache_holds(j, q)) {
    // With the gradient always: a value is mostly followed by derivatives at the same state.
    cached.value = joint_limit_coordinate(f, q, &cached.gc, &cached.gp);
    cached.qc = body_q(q, f.spec.child);
    cached.qp = body_q(q, f.spec.parent);
    cached.valid = true;
  }
  if (grad_child) *grad_child = cached.gc;
  if (grad_parent) *grad_parent = cached.gp;
  return cached.value;
}

bool JointSet::cached_coordinate(int j, const VecX& q, double& value) const {
  if (!cache_holds(j, q)) return false;
  value = coordinate_cache_[j].value;
  return true;
}

// The hinge angle nearest to the last one (no wrap at ±π, as MuJoCo's hinge qpos). At the
// state the solver last evaluated the joint at (the step's end, where the joint forces'
// step-end energy read it) the cached coordinate serves (`cached`: end_step, within the
// step): the same bits as hinge_angle.
double JointSet::unwrapped_angle(int j, const VecX& q, bool cached) const {
  double a;
  if (!cached)
    a = hinge_angle(frames_[j], q);
  else if (!cached_coordinate(j, q, a))
    // Not evaluated there yet (no step-end energies): into the cache when a term reads it
    // (the next step starts at q), else alone.
    a = coordinates_read_ ? coordinate(j, q, nullptr, nullptr) : hinge_angle(frames_[j], q);
  const double two_pi = 2.0 * M_PI;
  return a + two_pi * std::round((last_angle_[j] - a) / two_pi);
}

void JointSet::end_step(const VecX& q, const VecX& /*q_dot*/) {
  for (int j = 0; j < size(); ++j)
    if (frames_[j].spec.kind == JointKind::kRevolute) last_angle_[j] = unwrapped_angle(j, q, true);
  last_q_ = q;
}

void JointSet::reset(const VecX& q) {
  std::fill(last_angle_.begin(), last_angle_.end(), 0.0);
  end_step(q, q);
}

VecX JointSet::positions(const VecX& q) const {
  VecX out = VecX::Zero(nq_);
  // At the last end_step's state, unwrapping the angle again gives last_angle_ itself.
  const bool at_last = at_last_end_step(q);
  for (int j = 0; j < size(); ++j) {
    if (frames_[j].spec.kind == JointKind::kRevolute)  // (joint_position's angle, unwrapped)
      out[q_offset_[j]] = at_last ? last_angle_[j] : unwrapped_angle(j, q, false);
    else
      joint_position(frames_[j], q, out.data() + q_offset_[j]);
  }
  return out;
}

VecX JointSet::velocities(const VecX& q, const VecX& q_dot) const {
  VecX out = VecX::Zero(nv_);
  for (int j = 0; j < size(); ++j) joint_velocity(frames_[j], q, q_dot, out.data() + v_offset_[j]);
  return out;
}

}  // namespace abd
