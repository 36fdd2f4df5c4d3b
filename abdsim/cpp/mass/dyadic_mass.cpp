#include "mass/dyadic_mass.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace abd {
namespace {

// Reference point for the integrals: the vertex centroid. Integrating relative to it keeps
// the closed forms accurate for meshes placed far from the origin.
Vec3 reference_point(const MatX3& V) {
  if (V.rows() == 0) return Vec3::Zero();
  return V.colwise().mean().transpose();
}

// Tetrahedron (p0..p3 relative to the reference point), D = 6 × signed volume.
DyadicMass tet_contribution(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3,
                            double rho) {
  DyadicMass d;
  const double D = (p1 - p0).dot((p2 - p0).cross(p3 - p0));
  const Vec3 sum = p0 + p1 + p2 + p3;
  d.m = rho * D / 6.0;
  d.m_x_bar = rho * D * sum / 24.0;
  const Mat3 outer = p0 * p0.transpose() + p1 * p1.transpose() + p2 * p2.transpose() +
                     p3 * p3.transpose() + sum * sum.transpose();
  d.S = rho * D / 120.0 * outer;
  return d;
}

void check_rho(double rho) {
  if (!(rho > 0.0) || !std::isfinite(rho))
    throw std::invalid_argument("mass_density must be a positive finite number");
}

// These functions are reachable from Python with arbitrary arrays: every index is checked
// before it is used, so bad input is an exception naming the element, never a read out of
// range.
void check_vertices(const MatX3& V, const char* fn) {
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (!V.row(i).allFinite())
      throw std::invalid_argument(std::string(fn) + ": vertex " + std::to_string(i) +
                                  " has a NaN or infinite coordinate");
}

template <class Cells>
void check_cells(const Cells& C, Eigen::Index n_vertices, const char* fn, const char* what) {
  for (Eigen::Index c = 0; c < C.rows(); ++c)
    for (Eigen::Index k = 0; k < C.cols(); ++k)
      if (C(c, k) < 0 || C(c, k) >= n_vertices)
        throw std::out_of_range(std::string(fn) + ": " + what + " " + std::to_string(c) +
                                " has vertex index " + std::to_string(C(c, k)) +
                                " out of range [0, " + std::to_string(n_vertices) + ")");
}

void check_thickness(const VecX& r, Eigen::Index n_vertices, const char* fn) {
  if (r.size() != n_vertices)
    throw std::invalid_argument(std::string(fn) + ": thickness has " + std::to_string(r.size()) +
                                " values for " + std::to_string(n_vertices) + " vertices");
  for (Eigen::Index i = 0; i < r.size(); ++i)
    if (!(std::isfinite(r[i]) && r[i] > 0.0))
      throw std::invalid_argument(std::string(fn) + ": thickness of vertex " + std::to_string(i) +
                                  " must be positive and finite, got " + std::to_string(r[i]));
}

template <class Cells>
void check_mesh(const MatX3& V, const Cells& C, const char* fn, const char* what) {
  check_vertices(V, fn);
  check_cells(C, V.rows(), fn, what);
}

void check_finite_mass(double m, const Vec3& mx, const Mat3& S, const char* fn) {
  if (!(std::isfinite(m) && mx.allFinite() && S.allFinite()))
    throw std::invalid_argument(std::string(fn) + ": the dyadic mass must be finite");
}

}  // namespace

DyadicMass DyadicMass::shifted_by(const Vec3& o) const {
  DyadicMass d;
  d.m = m;
  d.m_x_bar = m_x_bar + m * o;
  d.S = S + m_x_bar * o.transpose() + o * m_x_bar.transpose() + m * o * o.transpose();
  return d;
}

Mat12 DyadicMass::matrix() const {
  Mat12 M = Mat12::Zero();
  M.block<3, 3>(0, 0) = m * Mat3::Identity();
  for (int i = 0; i < 3; ++i) {
    M.block<1, 3>(i, 3 + 3 * i) = m_x_bar.transpose();
    M.block<3, 1>(3 + 3 * i, i) = m_x_bar;
    M.block<3, 3>(3 + 3 * i, 3 + 3 * i) = S;
  }
  return M;
}

DyadicMass tet_mesh_mass(const MatX3& V, const MatX4i& T, double rho) {
  check_rho(rho);
  check_mesh(V, T, "tet_mesh_mass", "tetrahedron");
  const Vec3 o = reference_point(V);
  DyadicMass total;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    total += tet_contribution(V.row(T(t, 0)).transpose() - o, V.row(T(t, 1)).transpose() - o,
                              V.row(T(t, 2)).transpose() - o, V.row(T(t, 3)).transpose() - o,
                              rho);
  }
  return total.shifted_by(o);
}

DyadicMass closed_surface_mass(const MatX3& V, const MatX3i& F, double rho) {
  check_rho(rho);
  check_mesh(V, F, "closed_surface_mass", "triangle");
  const Vec3 o = reference_point(V);
  DyadicMass total;
  const Vec3 zero = Vec3::Zero();
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    total += tet_contribution(zero, V.row(F(f, 0)).transpose() - o,
                              V.row(F(f, 1)).transpose() - o, V.row(F(f, 2)).transpose() - o, rho);
  }
  return total.shifted_by(o);
}

DyadicMass shell_mass(const MatX3& V, const MatX3i& F, const VecX& r, double rho) {
  check_rho(rho);
  check_mesh(V, F, "shell_mass", "triangle");
  check_thickness(r, V.rows(), "shell_mass");
  const Vec3 o = reference_point(V);
  DyadicMass total;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Vec3 p0 = V.row(F(f, 0)).transpose() - o;
    const Vec3 p1 = V.row(F(f, 1)).transpose() - o;
    const Vec3 p2 = V.row(F(f, 2)).transpose() - o;
    const double rf = (r[F(f, 0)] + r[F(f, 1)] + r[F(f, 2)]) / 3.0;
    const Vec3 cross = (p1 - p0).cross(p2 - p0);
    const double area = 0.5 * cross.norm();
    if (!(area > 0.0)) continue;  // degenerate triangles are rejected in Python
    const Vec3 n = cross.normalized();
    const Vec3 sum = p0 + p1 + p2;
    const double mf = rho * area * 2.0 * rf;
    DyadicMass d;
    d.m = mf;
    d.m_x_bar = mf * sum / 3.0;
    d.S = mf / 12.0 *
              (p0 * p0.transpose() + p1 * p1.transpose() + p2 * p2.transpose() +
               sum * sum.transpose()) +
          // Slab term: without it a flat shell has a singular 12x12 mass matrix.
          rho * area * (2.0 * rf * rf * rf / 3.0) * n * n.transpose();
    total += d;
  }
  return total.shifted_by(o);
}

DyadicMass rod_mass(const MatX3& V, const MatX2i& E, const VecX& r, double rho) {
  check_rho(rho);
  check_mesh(V, E, "rod_mass", "edge");
  check_thickness(r, V.rows(), "rod_mass");
  const Vec3 o = reference_point(V);
  DyadicMass total;
  for (Eigen::Index e = 0; e < E.rows(); ++e) {
    const Vec3 p0 = V.row(E(e, 0)).transpose() - o;
    const Vec3 p1 = V.row(E(e, 1)).transpose() - o;
    const double re = 0.5 * (r[E(e, 0)] + r[E(e, 1)]);
    const double L = (p1 - p0).norm();
    if (!(L > 0.0)) continue;  // degenerate segments are rejected in Python
    const Vec3 t = (p1 - p0) / L;
    const double area = M_PI * re * re;
    const double me = rho * L * area;
    DyadicMass d;
    d.m = me;
    d.m_x_bar = me * 0.5 * (p0 + p1);
    d.S = me / 6.0 *
              (2.0 * p0 * p0.transpose() + p0 * p1.transpose() + p1 * p0.transpose() +
               2.0 * p1 * p1.transpose()) +
          // Cross-section term: a straight rod is otherwise singular about its axis.
          rho * L * (M_PI * re * re * re * re / 4.0) * (Mat3::Identity() - t * t.transpose());
    total += d;
  }
  return total.shifted_by(o);
}

RigidBodyProperties to_rigid_body(const DyadicMass& dm) {
  check_finite_mass(dm.m, dm.m_x_bar, dm.S, "to_rigid_body");
  if (!(dm.m > 0.0)) throw std::invalid_argument("to_rigid_body: mass must be positive");
  RigidBodyProperties rb;
  rb.mass = dm.m;
  rb.center = dm.m_x_bar / dm.m;
  const Mat3 I_O = dm.S.trace() * Mat3::Identity() - dm.S;
  const Vec3& c = rb.center;
  rb.inertia = I_O - dm.m * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  rb.inertia = 0.5 * (rb.inertia + rb.inertia.transpose());
  return rb;
}

DyadicMass from_rigid_body(double mass, const Vec3& center, const Mat3& inertia) {
  if (!(mass > 0.0) || !std::isfinite(mass))
    throw std::invalid_argument("from_rigid_body: mass must be a positive finite number");
  if (!(center.allFinite() && inertia.allFinite()))
    throw std::invalid_argument("from_rigid_body: mass_center and inertia must be finite");
  DyadicMass dm;
  dm.m = mass;
  dm.m_x_bar = mass * center;
  const Mat3 I_O =
      inertia + mass * (center.squaredNorm() * Mat3::Identity() - center * center.transpose());
  dm.S = 0.5 * I_O.trace() * Mat3::Identity() - I_O;
  dm.S = 0.5 * (dm.S + dm.S.transpose());
  return dm;
}

}  // namespace abd
