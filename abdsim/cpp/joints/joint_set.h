// The joints of a scene as one Constraint (solver/constraint.h): exact equality rows in the
// Newton solve, joint coordinates (unwrapped hinge angles) and violations.
#pragma once
#include <string>
#include <vector>

#include "common/same_bits.h"
#include "joints/joint_spec.h"
#include "solver/constraint.h"
#include "solver/scene_data.h"

namespace abd {

class JointSet : public Constraint {
 public:
  // q0: the bodies' states at load (the joints' reference configuration). Throws
  // std::invalid_argument naming the joint for a bad joint (bodies out of range, parent ==
  // child, zero axis, anchor far from both bodies, a child with two parents, a loop).
  JointSet(const SceneData& scene, const VecX& q0, const std::vector<JointSpec>& specs);

  std::string name() const override { return "joints"; }
  void linearize(const VecX& q, std::vector<ConstraintRow>& rows) const override;
  void values(const VecX& q, std::vector<ConstraintValue>& out) const override;
  // The values of the prismatic joints on a moving parent (the joints whose rows are not
  // linear).
  void nonlinear_values(const VecX& q, std::vector<ConstraintValue>& out) const override;
  void linearize_with_values(const VecX& q, const ConstraintValue* known,
                             std::vector<ConstraintRow>& rows) const override;
  bool linear() const override { return linear_; }
  void body_links(std::vector<BodyLink>& links) const override;
  void mark_bodies(std::vector<unsigned char>& marked) const override;
  ConstraintViolation violation(const VecX& q) const override;
  void end_step(const VecX& q, const VecX& q_dot) override;

  int size() const { return static_cast<int>(frames_.size()); }
  const JointFrame& frame(int j) const { return frames_.at(j); }
  int nq() const { return nq_; }
  int nv() const { return nv_; }
  // Offsets of each joint's coordinates in positions() / velocities().
  int q_offset(int j) const { return q_offset_.at(j); }
  int v_offset(int j) const { return v_offset_.at(j); }
  // Joint coordinates at q (hinge angles unwrapped against the last end_step).
  VecX positions(const VecX& q) const;
  VecX velocities(const VecX& q, const VecX& q_dot) const;
  // Whether q is the state of the last end_step, where positions() reads last_angle().
  bool at_last_end_step(const VecX& q) const { return same_bits(last_q_, q); }
  // Joint j's unwrapped hinge angle at the last end_step (0 for other joints).
  double last_angle(int j) const { return last_angle_[j]; }
  // Restarts the unwrapping from q (after a teleport).
  void reset(const VecX& q);
  // The coordinate of 1-dof joint j at q (joint_limit_coordinate's value, not unwrapped) and
  // its gradients (if non-null), kept per joint with the two bodies' states it was computed
  // at: a step evaluates each joint at the same state several times (the joint forces' Π
  // and derivatives at an iterate, the step-end energies, this set's end_step and the next
  // step's start). A hit is proved by those states' bits alone and returns what computing
  // again would (the coordinate is a function of them; its value does not depend on
  // whether gradients are asked for). For the solver's serial calls within a step only:
  // positions() (which Python may call) does not use it.
  double coordinate(int j, const VecX& q, Vec12* grad_child, Vec12* grad_parent) const;

 private:
  double unwrapped_angle(int j, const VecX& q, bool cached) const;

  std::vector<JointFrame> frames_;
  // Per joint with linear rows: its rows (their gradients are constant), which linearize()
  // copies and gives their values at q; empty for the others.
  std::vector<std::vector<ConstraintRow>> linear_rows_;
  std::vector<int> q_offset_, v_offset_;
  std::vector<double> last_angle_;  // unwrapped hinge angle at the last end_step
  // The state of the last end_step: positions() there are last_angle_ to the bit (the next
  // step begins there and reads them again).
  VecX last_q_;
  struct CoordinateCache {
    bool valid = false;
    Vec12 qc, qp;
    double value = 0.0;
    Vec12 gc, gp;
  };
  mutable std::vector<CoordinateCache> coordinate_cache_;  // per joint (coordinate())
  mutable bool coordinates_read_ = false;  // coordinate() was called (a term reads them)
  // Whether joint j's cache was computed at q's states (the two bodies' bits).
  bool cache_holds(int j, const VecX& q) const;
  // The cached value of joint j when it was computed at q's states (else false).
  bool cached_coordinate(int j, const VecX& q, double& value) const;
  int nq_ = 0, nv_ = 0;
  bool linear_ = true;
};

}  // namespace abd
