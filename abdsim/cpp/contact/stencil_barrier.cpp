#include "contact/stencil_barrier.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "common/psd.h"
#include "contact/barrier_projection.h"
#include "contact/barrier/barrier.h"
#include "contact/distance/edge_edge_mollifier.h"

namespace abd::contact {
namespace {

Mollifier stencil_mollifier(const ContactStencil& s, const std::vector<Vec3>& x, int order) {
  if (s.kind != StencilKind::EdgeEdge) return {};
  const auto& v = s.vertices;
  return edge_edge_mollifier_derivatives(x[v[0]], x[v[1]], x[v[2]], x[v[3]], s.eps_x, order);
}

// The PSD projection of the Hessian H of a function of k vertices that moving them all by the
// same vector leaves unchanged (a distance, the edge–edge mollifier): H t = 0 for every such
// translation t, so H = Q (Qᵀ H Q) Qᵀ with Q an orthonormal basis of the 3(k − 1) relative
// motions, and its projection is Q P(Qᵀ H Q) Qᵀ: the eigen-decomposition runs on a 9×9
// matrix instead of a 12×12 one (point–triangle, edge–edge), about 40% of the work; the
// eigen-decompositions were 15% of a heap of 100 boxes' step. Q's columns are the Helmert
// contrasts (vertices 0..j against vertex j + 1), one per axis.
StencilMat project_psd_translation_free(const StencilMat& H, int k) {
  if (k < 2) return project_psd(H);
  StencilMat Q = StencilMat::Zero(3 * k, 3 * (k - 1));
  for (int j = 0; j + 1 < k; ++j) {
    const double w = 1.0 / std::sqrt(double((j + 1) * (j + 2)));
    for (int i = 0; i <= j + 1; ++i) {
      const double c = i <= j ? w : -(j + 1) * w;
      Q.block<3, 3>(3 * i, 3 * j) = c * Mat3::Identity();
    }
  }
  const StencilMat reduced = Q.transpose() * H * Q;
  return Q * project_psd(reduced) * Q.transpose();
}

// PSD projection restricted to the vertices the Hessian involves. Degenerate pieces
// (point–point, point–edge) leave whole vertex blocks zero; projecting the non-zero principal
// block alone gives the same result (a zero block stays zero) for a fraction of the cost of a
// 12×12 eigen-decomposition.
StencilMat project_psd_on_support(const StencilMat& H, int nv) {
  std::array<int, kMaxStencilVertices> used{};
  int n_used = 0;
  for (int i = 0; i < nv; ++i)
    if (!H.middleRows(3 * i, 3).isZero(0.0)) used[n_used++] = i;
  if (n_used == nv) return project_psd_translation_free(H, nv);
  StencilMat sub(3 * n_used, 3 * n_used);
  for (int a = 0; a < n_used; ++a)
    for (int b = 0; b < n_used; ++b)
      sub.block<3, 3>(3 * a, 3 * b) = H.block<3, 3>(3 * used[a], 3 * used[b]);
  sub = project_psd_translation_free(sub, n_used);
  StencilMat out = StencilMat::Zero(3 * nv, 3 * nv);
  for (int a = 0; a < n_used; ++a)
    for (int b = 0; b < n_used; ++b)
      out.block<3, 3>(3 * used[a], 3 * used[b]) = sub.block<3, 3>(3 * a, 3 * b);
  return out;
}

}  // namespace

StencilEnergy stencil_barrier(const ContactStencil& s, const std::vector<Vec3>& x,
                              const BarrierParams& p, int order) {
  const int n = 3 * s.nv;
  StencilEnergy e;
  if (order >= 1) e.grad = StencilVec::Zero(n);
  if (order >= 2) e.hess = StencilMat::Zero(n, n);
  // The structured projection needs the distance Hessian's factors, not the dense matrix:
  // it is computed only where that projection does not apply (the mollifier, degenerate
  // input), below.
  const bool structured = order >= 2 && p.project_psd && s.kind != StencilKind::PointGround;
  StencilGeometry g = stencil_geometry(s, x, p.ground_height, order, false, !structured);
  if (order < 1) {
    e.value = stencil_barrier_value(s, {g.d2, g.infeasible}, x, p);
    return e;
  }
  if (g.infeasible) {
    e.value = std::numeric_limits<double>::infinity();
    return e;
  }
  const double d_reach = p.d_hat + s.xi;
  if (g.d2 >= d_reach * d_reach) return e;

  const double b = barrier(g.d2, p.d_hat, s.xi);
  const Mollifier m = stencil_mollifier(s, x, order);
  e.value = p.kappa * m.value * b;
  const double b1 = barrier_first_derivative(g.d2, p.d_hat, s.xi);
  e.grad = p.kappa * m.value * b1 * g.grad;
  if (m.active) e.grad += p.kappa * b * m.grad;
  if (order < 2) return e;
  const double b2 = barrier_second_derivative(g.d2, p.d_hat, s.xi);
  // Without the mollifier the projection works in the distance Hessian's structure
  // (barrier_projection.h), on at most 5x5 instead of 9x9.
  if (structured) {
    if (!m.active &&
        project_barrier_hessian(g, p.kappa * m.value * b2, p.kappa * m.value * b1, e.hess))
      return e;
    g = stencil_geometry(s, x, p.ground_height, order);  // with the dense Hessian
  }
  e.hess = p.kappa * m.value * (b2 * g.grad * g.grad.transpose() + b1 * g.hess);
  if (m.active) {
    // product rule for m · b(d²): cross terms and the mollifier's own curvature
    const StencilMat cross = m.grad * g.grad.transpose();
    e.hess += p.kappa * (b1 * (cross + cross.transpose()) + b * m.hess);
  }
  if (p.project_psd) {
    if (s.kind == StencilKind::PointGround) {
      // d² = (z − h)²: the Hessian is c e_z e_zᵀ, its projection max(c, 0) e_z e_zᵀ
      e.hess(2, 2) = std::max(e.hess(2, 2), 0.0);
    } else {
      e.hess = project_psd_on_support(e.hess, s.nv);
    }
  }
  return e;
}

double stencil_barrier_value(const ContactStencil& s, const StencilDistance& d,
                             const std::vector<Vec3>& x, const BarrierParams& p) {
  if (d.infeasible) return std::numeric_limits<double>::infinity();
  const double d_reach = p.d_hat + s.xi;
  if (d.d2 >= d_reach * d_reach) return 0.0;
  return p.kappa * stencil_mollifier(s, x, 0).value * barrier(d.d2, p.d_hat, s.xi);
}

double stencil_normal_force(const ContactStencil& s, const StencilGeometry& g,
                            const std::vector<Vec3>& x, const BarrierParams& p) {
  if (g.infeasible) return 0.0;
  const double m = stencil_mollifier(s, x, 0).value;
  return m * barrier_force_magnitude(g.d2, p.d_hat, s.xi, p.kappa);
}

}  // namespace abd::contact
