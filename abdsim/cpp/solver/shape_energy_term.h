// The shape-preservation energy Σ_b κ_b v̄_b Ψ_b(A_b) of every body as an EnergyTerm.
// The World calls the per-body functions directly in its fused per-body loops; the
// EnergyTerm interface serves generic callers (tests, other solvers).
#pragma once
#include <vector>

#include "solver/energy_term.h"
#include "solver/scene_data.h"

namespace abd {

class ShapeEnergyTerm : public EnergyTerm {
 public:
  explicit ShapeEnergyTerm(const SceneData& scene, bool project_psd = true);

  std::string name() const override { return "shape"; }
  double value(const VecX& q) const override;
  void add_gradient(const VecX& q, double scale, VecX& gradient) const override;
  void add_hessian(const VecX& q, double scale, std::vector<BodyBlock>& blocks) const override;

  int num_bodies() const { return static_cast<int>(uid_.size()); }
  double body_value(int b, const Vec12& q) const;
  // Adds scale * ∇E_b to g and scale * (PSD) ∇²E_b to H; returns E_b. `absorb`: a lower
  // bound on the smallest eigenvalue of what H holds already (the kinetic term's): the
  // OrthoPotential's clamp of negative eigenvalues is skipped when they are provably smaller
  // than that, so that H stays positive definite with the exact Hessian added.
  double add_body_derivatives(int b, const Vec12& q, double scale, Vec12& g, Mat12& H,
                              double absorb = 0.0) const;

 private:
  std::vector<int> uid_;
  std::vector<double> weight_;  // κ v̄
  bool project_psd_;
};

}  // namespace abd
