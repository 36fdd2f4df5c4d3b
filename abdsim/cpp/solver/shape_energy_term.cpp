#include "solver/shape_energy_term.h"

#include <Eigen/Eigenvalues>
#include <stdexcept>
#include <string>

#include "common/affine.h"
#include "common/psd.h"
#include "energy/arap.h"
#include "energy/ortho_potential.h"
#include "energy/shape_energy.h"

namespace abd {
namespace {

// Below this smallest eigenvalue of AAᵀ − I the OrthoPotential Hessian is projected by a
// full eigen-decomposition; above it (the near-rigid state every step is in) a shift does.
// Near rigidity the Hessian's rotational eigenvalues are O(λ(R)), of either sign: clamping
// them or shifting every eigenvalue by 4|λ_min(R)| changes them by the same order, and the
// stretch eigenvalues (≈ 8) by at most 0.5 %.
constexpr double kOrthoShiftLimit = 1e-2;

bool psd3(const Mat3& R) {
  // Sylvester's criterion for semi-definiteness: every principal minor is >= 0.
  if (R(0, 0) < 0.0 || R(1, 1) < 0.0 || R(2, 2) < 0.0) return false;
  if (R(0, 0) * R(1, 1) - R(0, 1) * R(1, 0) < 0.0) return false;
  if (R(0, 0) * R(2, 2) - R(0, 2) * R(2, 0) < 0.0) return false;
  if (R(1, 1) * R(2, 2) - R(1, 2) * R(2, 1) < 0.0) return false;
  return R.determinant() >= 0.0;
}

// OrthoPotential Ψ = ‖AAᵀ − I‖²_F: value, ws·gradient and ws·Hessian in one pass. The
// formulas of energy/ortho_potential.cpp, regrouped around R = AAᵀ − I:
//   ∂Ψ/∂A = 4 R A,   ∂²Ψ/∂a_i∂a_j = 4 a_j a_iᵀ + 4 δ_ij AᵀA + 4 R_ij I.
// The Hessian is 2 JᵀJ + 4 (R ⊗ I₃) (J the Jacobian of AAᵀ), hence PSD whenever R is, and
// ∇²Ψ − 4 λ_min(R) I is PSD for any A. Projection: nothing when R is PSD; the shift when
// λ_min(R) >= −kOrthoShiftLimit (near rigidity, where every step spends its time); an exact
// eigenvalue clamp otherwise.
double ortho_derivatives(const Mat3& A, bool project, double ws, Vec12& g, Mat12& H) {
  const Mat3 R = A * A.transpose() - Mat3::Identity();
  const Mat3 G = 4.0 * R * A;
  for (int i = 0; i < 3; ++i) g.segment<3>(3 + 3 * i) += ws * G.row(i).transpose();
  Mat9 Hs;
  const Mat3 AtA = A.transpose() * A;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      Mat3 block = A.row(j).transpose() * A.row(i);
      if (i == j) block += AtA;
      block.diagonal().array() += R(i, j);
      Hs.block<3, 3>(3 * i, 3 * j) = 4.0 * block;
    }
  if (project && !psd3(R)) {
    Eigen::SelfAdjointEigenSolver<Mat3> eig;
    eig.computeDirect(R, Eigen::EigenvaluesOnly);
    const double lambda_min = eig.eigenvalues()[0];
    if (lambda_min >= -kOrthoShiftLimit) {
      if (lambda_min < 0.0) Hs.diagonal().array() -= 4.0 * lambda_min;
    } else {
      Hs = project_psd(Hs);
    }
  }
  H.bottomRightCorner<9, 9>() += ws * Hs;
  return R.squaredNorm();
}

}  // namespace

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
                                             Mat12& H) const {
  const Mat3 A = affine_A(q);
  const double w = weight_[b];
  const double ws = w * scale;
  if (uid_[b] == kOrthoPotential) return w * ortho_derivatives(A, project_psd_, ws, g, H);
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
