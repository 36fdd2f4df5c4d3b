// External wrenches on bodies (like MuJoCo's xfrc_applied) as a linear energy term: a force
// F at a material point x̄ does the work F·J(x̄)q; a torque τ does τ·δφ with the rotation
// increment δφ = vee(skew((A − A_t) A_t⁻¹)) from the step start (exact to first order for a
// rigid motion). Wrenches persist until replaced or cleared.
#pragma once
#include <string>
#include <vector>

#include "solver/energy_term.h"
#include "solver/scene_data.h"

namespace abd {

class BodyWrenchTerm : public EnergyTerm {
 public:
  explicit BodyWrenchTerm(int n_bodies) : n_(n_bodies) {}
  std::string name() const override { return "applied_wrench"; }

  // The force acts at the material point x̄ (rest coordinates).
  void set_wrench(int body, const Vec3& force, const Vec3& torque, const Vec3& x_bar);
  void clear();

  void begin_step(const StepContext& ctx) override;
  double value(const VecX& q) const override;
  void add_gradient(const VecX& q, double scale, VecX& gradient) const override;
  void add_hessian(const VecX&, double, std::vector<BodyBlock>&) const override {}

  bool splits_by_body() const override { return true; }
  void add_body_values(const VecX& q, const std::vector<unsigned char>& movable,
                       VecX& per_body, std::vector<BodyLink>& links) const override;
  // Bodies under a wrench never keep the free per-body solution (it does not see them).
  void body_max_steps(const VecX& q, const VecX& dq, const std::vector<unsigned char>& movable,
                      VecX& bound, std::vector<unsigned char>& near,
                      std::vector<BodyLink>& links) const override;
  void mark_forced_bodies(std::vector<unsigned char>& flags) const override;

 private:
  struct Wrench {
    int body;
    Vec3 force, torque, x_bar;
    Mat3 A_t_inv = Mat3::Identity();
    Mat3 A_t = Mat3::Identity();
  };
  Vec12 gradient_of(const Wrench& w) const;  // ∂E/∂q_body (constant)
  int n_;
  std::vector<Wrench> wrenches_;
};

}  // namespace abd
