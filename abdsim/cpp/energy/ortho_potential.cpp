#include "energy/ortho_potential.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

namespace abd {
namespace {

// Sylvester's criterion for semi-definiteness: every principal minor is >= 0.
bool psd3(const Mat3& R) {
  if (R(0, 0) < 0.0 || R(1, 1) < 0.0 || R(2, 2) < 0.0) return false;
  if (R(0, 0) * R(1, 1) - R(0, 1) * R(1, 0) < 0.0) return false;
  if (R(0, 0) * R(2, 2) - R(0, 2) * R(2, 0) < 0.0) return false;
  if (R(1, 1) * R(2, 2) - R(1, 2) * R(2, 1) < 0.0) return false;
  return R.determinant() >= 0.0;
}

// A 3x3 matrix flattened row by row (the layout of A's rows in q).
Vec9 flatten_rows(const Mat3& M) {
  Vec9 v;
  for (int r = 0; r < 3; ++r) v.segment<3>(3 * r) = M.row(r).transpose();
  return v;
}


// True when no eigenvalue of ∇²Ψ can be negative, told from M = AᵀA without its eigen-solve
// (for_negative_modes lists the modes: 12μ_i − 4 and 4(μ_i + μ_j − 1 ± σ_iσ_j), μ = σ² the
// eigenvalues of M). As σ_iσ_j ≤ (μ_i + μ_j)/2, the "−" modes are at least 2(μ_i + μ_j − 2),
// the eigenvalues of 2((tr M − 2) I − M) (k, the third index, takes μ_k off the trace); the
// "+" modes are larger. So when (tr M − 2) I − M and M − I/3 are both positive definite by
// a margin, the projection has nothing to remove and returns the exact Hessian as it stands:
// the same bits, without the eigen-solve. The margin (1e-10 of M's scale) keeps the test
// clear of that solve's round-off (~1e-16 on μ), so that no mode it would find rounded
// below zero is skipped. The bound is tight to first order in μ − 1 (a body at rest is
// clear unless it is compressed along some axis, where the projection does remove modes).
bool no_negative_modes(const Mat3& AtA) {
  const double trace = AtA.trace();
  const double margin = 1e-10 * trace;
  Mat3 minus_bound = -AtA;
  minus_bound.diagonal().array() += trace - 2.0 - margin;
  Mat3 diagonal_modes = AtA;
  diagonal_modes.diagonal().array() -= 1.0 / 3.0 + margin;
  return psd3(minus_bound) && psd3(diagonal_modes);
}

// A bound on how far below zero the eigenvalues of ∇²Ψ reach, from M = AᵀA without its
// eigen-solve: with μ the eigenvalues of M, the "−" modes are at least 2(μ_i + μ_j − 2) (see
// no_negative_modes) and the diagonal ones 12μ_i − 4, both >= 4(μ_min − 1) when μ_min >= 0;
// Gershgorin's discs bound μ_min from below. Infinite when that bound is negative.
double negative_curvature_bound(const Mat3& AtA) {
  double lowest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i)
    lowest = std::min(lowest, AtA(i, i) - std::abs(AtA(i, (i + 1) % 3)) -
                                  std::abs(AtA(i, (i + 2) % 3)));
  if (!(lowest >= 0.0)) return std::numeric_limits<double>::infinity();
  return 4.0 * std::max(0.0, 1.0 - lowest);
}

// Closed-form eigen-system of ∇²Ψ. With A = U Σ Vᵀ (SVD) and δA = U X Vᵀ (an orthogonal
// change of variables), AAᵀ − I = U(Σ² − I)Uᵀ and
//   δAᵀ∇²Ψ δA = 2‖XΣ + ΣXᵀ‖² + 4 Σ_ij (σ_i² − 1) X_ij²,
// which splits into
//   X_ii:               eigenvalue 12σ_i² − 4,                      direction u_i v_iᵀ;
//   (X_ij, X_ji), i<j:  4(σ_i² + σ_j² − 1 ± σ_i σ_j),               (u_i v_jᵀ ± u_j v_iᵀ)/√2.
// At a rotation the "−" modes (δA = W A, W skew: the rotations) have eigenvalue 0 and the
// others 8. The projection subtracts the negative modes (there are at most a few, and
// usually only slightly negative rotational ones) from the exact Hessian: remove(λ, e) for
// each eigenvalue λ < 0 with its unit direction e, given AᵀA. A mode's direction is built
// only when its eigenvalue is negative (near rest: some of the three rotational modes, the
// others never).
template <class Remove>
void for_negative_modes(const Mat3& A, const Mat3& AtA, Remove&& remove) {
  Mat3 U, V;
  Vec3 s;
  // V and Σ² from AᵀA in closed form (cheap; the simulator calls this in its inner loop),
  // U = A V Σ⁻¹; a nearly singular A takes the full SVD instead.
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(AtA);
  const Vec3 s2 = eig.eigenvalues();
  if (s2[0] > 1e-6 * s2[2] && s2[0] > 0.0) {
    V = eig.eigenvectors();
    s = s2.cwiseSqrt();
    U = A * V * s.cwiseInverse().asDiagonal();
  } else {
    const Eigen::JacobiSVD<Mat3> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
    U = svd.matrixU();
    V = svd.matrixV();
    s = svd.singularValues();
  }
  for (int i = 0; i < 3; ++i) {
    const double lambda = 12.0 * s[i] * s[i] - 4.0;
    if (lambda < 0.0) remove(lambda, flatten_rows(U.col(i) * V.col(i).transpose()));
  }
  const double inv_sqrt2 = 1.0 / std::sqrt(2.0);
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) {
      const double base = s[i] * s[i] + s[j] * s[j] - 1.0;
      const double plus = 4.0 * (base + s[i] * s[j]), minus = 4.0 * (base - s[i] * s[j]);
      if (!(plus < 0.0) && !(minus < 0.0)) continue;
      const Mat3 Eij = U.col(i) * V.col(j).transpose();
      const Mat3 Eji = U.col(j) * V.col(i).transpose();
      if (plus < 0.0) remove(plus, flatten_rows(inv_sqrt2 * (Eij + Eji)));
      if (minus < 0.0) remove(minus, flatten_rows(inv_sqrt2 * (Eij - Eji)));
    }
}

// ws·∇²Ψ added to a body's 12x12 block H (A's rows: its entries 3..11) in one pass. The
// exact Hessian, regrouped around R = AAᵀ − I:
//   ∂²Ψ/∂a_i∂a_j = 4 a_j a_iᵀ + 4 δ_ij AᵀA + 4 R_ij I,
// i.e. 2 JᵀJ + 4 (R ⊗ I₃) with J the Jacobian of AAᵀ: PSD whenever R is. Entry by entry,
// (3i + a, 3j + b) = 4 (A_ja A_ib [+ (AᵀA)_ab if i = j] [+ R_ij if a = b]), scaled where it is
// added (a 9x9 temporary scaled and then added was a third of a Panda link's shape-energy
// instructions). Each pair of blocks (i, j), (j, i) takes the same value: H stays symmetric
// to the bit when it was.
void add_scaled_hessian(const Mat3& A, const Mat3& AtA, const Mat3& R, double ws, Mat12& H) {
  const double s = 4.0 * ws;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      for (int b = 0; b < 3; ++b)
        for (int a = 0; a < 3; ++a) {
          double v = A(j, a) * A(i, b);
          if (i == j) v += AtA(a, b);
          if (a == b) v += R(i, j);
          H(3 + 3 * i + a, 3 + 3 * j + b) += s * v;
          if (j != i) H(3 + 3 * j + b, 3 + 3 * i + a) += s * v;
        }
}

}  // namespace

double ortho_potential(const Mat3& A) {
  return (A * A.transpose() - Mat3::Identity()).squaredNorm();
}

double ortho_potential_add_body_derivatives(const Mat3& A, bool project, double ws, Vec12& g,
                                            Mat12* H, double absorb) {
  const Mat3 R = A * A.transpose() - Mat3::Identity();
  // ∂Ψ/∂a_i = 4(|a_i|²−1) a_i + 4 Σ_{j≠i} (a_i·a_j) a_j  ==  4 (AAᵀ − I) A, row i.
  g.tail<9>() += ws * flatten_rows(4.0 * R * A);
  if (H) {
    // No clamp where the kinetic term absorbs the negative curvature, where R is PSD (the
    // Hessian is then PSD as it stands, see add_scaled_hessian), or where no mode can be
    // negative; else the negative modes are removed.
    const Mat3 AtA = A.transpose() * A;
    add_scaled_hessian(A, AtA, R, ws, *H);
    // The cheapest test first (the kinetic term's absorb holds for a body near rest).
    if (project && !(ws * negative_curvature_bound(AtA) <= absorb) && !psd3(R) &&
        !no_negative_modes(AtA))
      for_negative_modes(A, AtA, [&](double lambda, const Vec9& e) {
        H->bottomRightCorner<9, 9>().noalias() -= (ws * lambda) * e * e.transpose();
      });
  }
  return R.squaredNorm();
}

}  // namespace abd
