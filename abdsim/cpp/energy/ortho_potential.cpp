#include "energy/ortho_potential.h"

namespace abd {

double ortho_potential(const Mat3& A) {
  return (A * A.transpose() - Mat3::Identity()).squaredNorm();
}

Vec9 ortho_potential_gradient(const Mat3& A) {
  // ∂Ψ/∂a_i = 4(|a_i|²−1) a_i + 4 Σ_{j≠i} (a_i·a_j) a_j  ==  4 (AAᵀ − I) A, row i.
  const Mat3 G = 4.0 * (A * A.transpose() - Mat3::Identity()) * A;
  Vec9 g;
  for (int i = 0; i < 3; ++i) g.segment<3>(3 * i) = G.row(i).transpose();
  return g;
}

Mat9 ortho_potential_hessian(const Mat3& A) {
  Mat9 H;
  const Mat3 I = Mat3::Identity();
  for (int i = 0; i < 3; ++i) {
    const Vec3 ai = A.row(i).transpose();
    for (int j = 0; j < 3; ++j) {
      const Vec3 aj = A.row(j).transpose();
      Mat3 block;
      if (i == j) {
        block = 8.0 * ai * ai.transpose() + 4.0 * (ai.squaredNorm() - 1.0) * I;
        for (int k = 0; k < 3; ++k) {
          if (k == i) continue;
          const Vec3 ak = A.row(k).transpose();
          block += 4.0 * ak * ak.transpose();
        }
      } else {
        block = 4.0 * aj * ai.transpose() + 4.0 * ai.dot(aj) * I;
      }
      H.block<3, 3>(3 * i, 3 * j) = block;
    }
  }
  return H;
}

}  // namespace abd
