#include "solver/shape_energy_term.h"

#include <stdexcept>
#include <string>

#include "common/affine.h"
#include "energy/arap.h"
#include "energy/ortho_potential.h"
#include "energy/shape_energy.h"

namespace abd {

ShapeEnergyTerm::ShapeEnergyTerm(const SceneData& scene, bool project_psd)
    : project_psd_(project_psd) {
  uid_.reserve(scene.bodies.size());
  weight_.reserve(scene.bodies.size());
  for (const BodyData& b : scene.bodies) {
    if (b.constitution_uid != kOrthoPotential && b.constitution_uid != kARAP)
      throw std::invalid_argument("unknown constitution_uid " +
                                  std::to_string(b.constitution_uid) +
                                  " (1 = OrthoPotential, 2 = ARAP)");
    uid_.push_back(b.constitution_uid);
    weight_.push_back(b.kappa * b.volume);
  }
}

double ShapeEnergyTerm::body_value(int b, const Vec12& q) const {
  const Mat3 A = affine_A(q);
  return weight_[b] * (uid_[b] == kOrthoPotential ? ortho_potential(A) : arap(A));
}

double ShapeEnergyTerm::add_body_derivatives(int b, const Vec12& q, double scale, Vec12& g,
                                             Mat12& H, double absorb) const {
  const Mat3 A = affine_A(q);
  const double w = weight_[b];
  const double ws = w * scale;
  if (uid_[b] == kOrthoPotential)
    return w * ortho_potential_add_body_derivatives(A, project_psd_, ws, g, &H, absorb);
  g.tail<9>() += ws * arap_gradient(A);
  H.bottomRightCorner<9, 9>() += ws * arap_hessian(A, project_psd_);
  return w * arap(A);
}

double ShapeEnergyTerm::value(const VecX& q) const {
  double e = 0.0;
  for (int b = 0; b < num_bodies(); ++b) e += body_value(b, q.segment<12>(12 * b));
  return e;
}

void ShapeEnergyTerm::add_gradient(const VecX& q, double scale, VecX& gradient) const {
  for (int b = 0; b < num_bodies(); ++b) {
    Vec12 g = Vec12::Zero();
    Mat12 H = Mat12::Zero();
    add_body_derivatives(b, q.segment<12>(12 * b), scale, g, H);
    gradient.segment<12>(12 * b) += g;
  }
}

void ShapeEnergyTerm::add_hessian(const VecX& q, double scale,
                                  std::vector<BodyBlock>& blocks) const {
  for (int b = 0; b < num_bodies(); ++b) {
    Vec12 g = Vec12::Zero();
    BodyBlock block{b, b, Mat12::Zero()};
    add_body_derivatives(b, q.segment<12>(12 * b), scale, g, block.H);
    blocks.push_back(block);
  }
}

}  // namespace abd
