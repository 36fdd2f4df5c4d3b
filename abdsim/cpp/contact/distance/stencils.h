// The four smooth distance pieces as affine stencils (see affine_distance.h), evaluated on a
// subset `idx` of a parent stencil's vertices and scattered back into the parent's dofs.
// A degenerate case of a primitive pair (e.g. point–triangle closest to an edge) is then just
// a smaller stencil over some of the pair's vertices; its unused vertices get zero weight.
#pragma once
#include <array>

#include "contact/distance/affine_distance.h"

namespace abd::contact::stencil {

template <int NV, int NS, int NB>
AffineDistance<NV> evaluate_on(const std::array<Vec3, NV>& x, const std::array<int, NS>& idx,
                               const Eigen::Matrix<double, NS, 1>& c,
                               const Eigen::Matrix<double, NS, NB>& a, int order,
                               bool dense_hessian = true) {
  std::array<Vec3, NS> xs;
  for (int k = 0; k < NS; ++k) xs[k] = x[idx[k]];
  const AffineDistance<NS> s = affine_distance<NS, NB>(xs, c, a, order, dense_hessian);
  AffineDistance<NV> out;
  out.d2 = s.d2;
  out.r = s.r;
  out.w.setZero();
  for (int k = 0; k < NS; ++k) out.w[idx[k]] = s.w[k];
  if (order >= 1) {
    out.grad.setZero();
    for (int k = 0; k < NS; ++k) out.grad.template segment<3>(3 * idx[k]) = s.grad.template segment<3>(3 * k);
  }
  if (order >= 2) {
    if (dense_hessian) {
      out.hess.setZero();
      for (int k = 0; k < NS; ++k)
        for (int l = 0; l < NS; ++l)
          out.hess.template block<3, 3>(3 * idx[k], 3 * idx[l]) = s.hess.template block<3, 3>(3 * k, 3 * l);
    }
    out.nb = s.nb;
    out.a.setZero();
    for (int k = 0; k < NS; ++k) out.a.row(idx[k]) = s.a.row(k);
    out.u = s.u;
    out.U_inv = s.U_inv;
  }
  return out;
}

// r = x_a − x_b
template <int NV>
AffineDistance<NV> point_point(const std::array<Vec3, NV>& x, std::array<int, 2> idx, int order,
                               bool dense_hessian = true) {
  const Eigen::Matrix<double, 2, 1> c(1.0, -1.0);
  const Eigen::Matrix<double, 2, 0> a;
  return evaluate_on<NV, 2, 0>(x, idx, c, a, order, dense_hessian);
}

// idx = {p, e0, e1}: r = p − e0 − s (e1 − e0), the infinite line through e0, e1
template <int NV>
AffineDistance<NV> point_line(const std::array<Vec3, NV>& x, std::array<int, 3> idx, int order,
                              bool dense_hessian = true) {
  const Eigen::Matrix<double, 3, 1> c(1.0, -1.0, 0.0);
  const Eigen::Matrix<double, 3, 1> a(0.0, 1.0, -1.0);
  return evaluate_on<NV, 3, 1>(x, idx, c, a, order, dense_hessian);
}

// idx = {p, t0, t1, t2}: r = p − t0 − β1 (t1 − t0) − β2 (t2 − t0), the plane of the triangle
template <int NV>
AffineDistance<NV> point_plane(const std::array<Vec3, NV>& x, std::array<int, 4> idx, int order,
                               bool dense_hessian = true) {
  const Eigen::Matrix<double, 4, 1> c(1.0, -1.0, 0.0, 0.0);
  Eigen::Matrix<double, 4, 2> a;
  a << 0.0, 0.0, 1.0, 1.0, -1.0, 0.0, 0.0, -1.0;
  return evaluate_on<NV, 4, 2>(x, idx, c, a, order, dense_hessian);
}

// idx = {a0, a1, b0, b1}: r = a0 + s (a1 − a0) − b0 − t (b1 − b0), two infinite lines
template <int NV>
AffineDistance<NV> line_line(const std::array<Vec3, NV>& x, std::array<int, 4> idx, int order,
                              bool dense_hessian = true) {
  const Eigen::Matrix<double, 4, 1> c(1.0, 0.0, -1.0, 0.0);
  Eigen::Matrix<double, 4, 2> a;
  a << -1.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, -1.0;
  return evaluate_on<NV, 4, 2>(x, idx, c, a, order, dense_hessian);
}

// A smooth piece of a typed distance: which stencil, over which of the pair's vertices.
enum class PieceKind { PointPoint, PointLine, PointPlane, LineLine };
struct Piece {
  PieceKind kind;
  std::array<int, 4> idx;  // the first 2, 3 or 4 entries are used
};

template <int NV>
AffineDistance<NV> evaluate_piece(const std::array<Vec3, NV>& x, const Piece& piece, int order,
                                  bool dense_hessian = true) {
  const auto& i = piece.idx;
  switch (piece.kind) {
    case PieceKind::PointPoint: return point_point<NV>(x, {i[0], i[1]}, order, dense_hessian);
    case PieceKind::PointLine: return point_line<NV>(x, {i[0], i[1], i[2]}, order, dense_hessian);
    case PieceKind::PointPlane: return point_plane<NV>(x, i, order, dense_hessian);
    default: return line_line<NV>(x, i, order, dense_hessian);
  }
}

}  // namespace abd::contact::stencil
