// Joint physics and actuation as one energy term (solver/energy_term.h) in the 1-dof joints'
// coordinates (joints/joint_potentials.h for the potentials): springs, viscous damping with
// the implicit velocity, armature, smoothed dry friction loss, limits as an IPC barrier with
// a step bound (never crossed), generalized forces (qfrc_applied) and MuJoCo-style motor /
// position / velocity actuators with gear, control and force ranges. θ(q) and its derivatives:
// joints/joint_limit_coordinate.h (the hinge angle in the parent's own frame). The Hessian is
// the Gauss–Newton one, E''(θ) ∇θ ∇θᵀ (PSD), plus, where a limit barrier pushes, its
// curvature term E'_limit ∇²θ (projected to PSD with it); gradients are exact.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "joints/joint_set.h"
#include "solver/energy_term.h"

namespace abd {

struct JointPhysics {
  double stiffness = 0.0;
  double ref = 0.0;
  double damping = 0.0;
  double armature = 0.0;
  double frictionloss = 0.0;
  bool limited = false;
  double lower = 0.0;
  double upper = 0.0;
};

enum class ActuatorKind : int { kMotor = 0, kPosition = 1, kVelocity = 2 };

struct ActuatorSpec {
  int joint = 0;
  ActuatorKind kind = ActuatorKind::kMotor;
  double kp = 0.0;
  double kv = 0.0;
  double gear = 1.0;
  // Constant force b0 (MuJoCo's biasprm[0]; a loader also folds b1·L at the loaded pose into it,
  // since joint coordinates start at 0 where the source's start at the loaded qpos).
  double bias = 0.0;
  bool ctrl_limited = false;
  double ctrl_lower = 0.0, ctrl_upper = 0.0;
  bool force_limited = false;
  double force_lower = 0.0, force_upper = 0.0;
};

class JointForceTerm : public EnergyTerm {
 public:
  // physics: one per joint of `joints` (only revolute and prismatic joints may have any);
  // throws std::invalid_argument naming the joint for bad values or a start outside limits.
  JointForceTerm(std::shared_ptr<const JointSet> joints, const SceneData& scene,
                 const std::vector<JointPhysics>& physics,
                 const std::vector<ActuatorSpec>& actuators);

  std::string name() const override { return "joints"; }
  void begin_step(const StepContext& ctx) override;
  // A limit barrier that engaged or let go during the step is a kink in the joint force:
  // BDF2 restarts there (as at contact changes).
  void update(const VecX& q) override;
  bool broke_smoothness() const override;
  double value(const VecX& q) const override;
  void add_gradient(const VecX& q, double scale, VecX& gradient) const override;
  void add_hessian(const VecX& q, double scale, std::vector<BodyBlock>& blocks) const override;
  void add_gradient_and_hessian(const VecX& q, double scale, VecX& gradient,
                                std::vector<BodyBlock>& blocks) const override;
  // Each joint's Hessian E''(θ) ∇θ ∇θᵀ as one rank-one row on its two bodies (a block for a
  // joint to the world).
  void add_gradient_and_hessian_rows(const VecX& q, double scale, VecX& gradient,
                                     std::vector<BodyBlock>& blocks,
                                     std::vector<HessianRow>& rows) const override;
  double max_step(const VecX& q, const VecX& dq) const override;
  // Bodies of joints with friction loss converge to 0.1 ε (their friction turns over ε).
  void limit_tolerances(VecX& tol_translation, VecX& tol_affine,
                        const std::vector<double>& radius) const override;

  bool splits_by_body() const override { return true; }
  void add_body_values(const VecX& q, const std::vector<unsigned char>& movable,
                       VecX& per_body, std::vector<BodyLink>& links) const override;
  void body_links(const std::vector<unsigned char>& movable,
                  std::vector<BodyLink>& links) const override;
  void body_max_steps(const VecX& q, const VecX& dq, const std::vector<unsigned char>& movable,
                      VecX& bound, std::vector<unsigned char>& near,
                      std::vector<BodyLink>& links) const override;
  void mark_forced_bodies(std::vector<unsigned char>& flags) const override;

  // Controls, one per actuator (clamped to ctrl ranges when used).
  VecX& ctrl() { return ctrl_; }
  // Generalized forces, one per joint (only 1-dof joints take a non-zero one).
  void set_joint_forces(const VecX& tau);
  const VecX& joint_forces() const { return tau_; }
  int num_actuators() const { return static_cast<int>(actuators_.size()); }

  static constexpr double kLimitMargin = 1e-3;   // barrier reach d̂ (rad or m)
  static constexpr double kFrictionSpeed = 1e-3;  // smoothing speed ε (rad/s or m/s)

 private:
  struct Element {  // a 1-dof joint with something acting on it
    int joint;
    double inertia;  // effective inertia about/along the axis (barrier scale)
    // per step
    double theta_t = 0.0, theta_hat = 0.0, theta_tilde = 0.0;
    double prev_theta = 0.0, prev_rate = 0.0;  // at the previous step start (BDF2)
    double start_theta = 0.0, start_rate = 0.0;  // at this step's start (a retry repeats it)
    bool has_prev = false, has_start = false;
    double kappa = 0.0;
    bool at_limit_start = false, at_limit = false;  // a barrier active (d < d̂)
  };
  bool at_limit(const Element& e, double theta) const;
  // θ at q, unwrapped against theta_t, and its gradients (JointSet::coordinate's cache).
  double theta_of(const Element& e, const VecX& q, Vec12* gc, Vec12* gp) const;
  // E and its first two derivatives in θ; limit_d1 (if non-null): the limit barriers' share
  // of d1 (their curvature term needs it). False where θ is outside the limits.
  bool energy(const Element& e, double theta, double& E, double& d1, double& d2,
              double* limit_d1 = nullptr) const;
  double limit_step(const Element& e, const VecX& q, const VecX& dq) const;
  // Gradient (if non-null) and Hessian (blocks non-null) in one pass over the joints: as
  // blocks, or (rows non-null) as rows where a joint has two bodies.
  void assemble(const VecX& q, double scale, VecX* gradient, std::vector<BodyBlock>* blocks,
                std::vector<HessianRow>* rows) const;


  std::shared_ptr<const JointSet> joints_;
  std::vector<JointPhysics> physics_;
  std::vector<ActuatorSpec> actuators_;
  std::vector<Element> elements_;
  std::vector<int> element_of_joint_;      // −1: nothing acts on the joint
  std::vector<std::vector<int>> actuators_of_;  // per element: its actuators, ascending
  std::vector<double> act_F0_, act_F1_;    // per actuator, this step: force = F0 + F1 θ
  VecX ctrl_, tau_;
  double c_ = 0.0;
};

}  // namespace abd
