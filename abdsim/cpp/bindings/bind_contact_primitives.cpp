// Bindings of the contact building blocks, named like ipctk's so tests can compare 1:1.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include "bindings/bind_contact_parts.h"
#include "contact/barrier/adaptive_stiffness.h"
#include "contact/barrier/barrier.h"
#include "contact/ccd/additive_ccd.h"
#include "contact/distance/distance.h"
#include "contact/distance/edge_edge_mollifier.h"
#include "contact/friction/closest_point.h"
#include "contact/friction/friction_potential.h"
#include "contact/friction/smooth_friction.h"
#include "contact/friction/tangent_basis.h"
#include "contact/ground/ground_plane.h"

namespace py = pybind11;

namespace abd::bindings {
namespace {
using namespace abd::contact;

// One Vec3 parameter per index of a pack (the bound functions take vertices one by one).
template <std::size_t>
using V3 = const Vec3&;

// Points handed in from Python: NaN would make a CCD report "no impact" (t = 1) and a
// distance NaN, silently.
template <class... P>
void check_points(const char* fn, const P&... p) {
  if (!(p.allFinite() && ...))
    throw std::invalid_argument(std::string(fn) + ": points must be finite");
}

template <class E>
void def_enum(py::module_& m, const char* name, std::initializer_list<const char*> values) {
  py::enum_<E> e(m, name);
  int i = 0;
  for (const char* v : values) e.value(v, E(i++));
}

// point_edge_<suffix>(p, e0, e1), point_triangle_<suffix>(p, t0, t1, t2) and
// edge_edge_<suffix>(ea0, ea1, eb0, eb1): the three pair kinds with their usual argument names.
template <class PE, class PT, class EE>
void def_pair_functions(py::module_& m, const std::string& suffix, PE pe, PT pt, EE ee) {
  m.def(("point_edge_" + suffix).c_str(), pe, py::arg("p"), py::arg("e0"), py::arg("e1"));
  m.def(("point_triangle_" + suffix).c_str(), pt, py::arg("p"), py::arg("t0"), py::arg("t1"),
        py::arg("t2"));
  m.def(("edge_edge_" + suffix).c_str(), ee, py::arg("ea0"), py::arg("ea1"), py::arg("eb0"),
        py::arg("eb1"));
}

void bind_distance_types(py::module_& m) {
  def_enum<PointEdgeDistanceType>(m, "PointEdgeDistanceType", {"P_E0", "P_E1", "P_E", "AUTO"});
  def_enum<PointTriangleDistanceType>(
      m, "PointTriangleDistanceType", {"P_T0", "P_T1", "P_T2", "P_E0", "P_E1", "P_E2", "P_T", "AUTO"});
  def_enum<EdgeEdgeDistanceType>(m, "EdgeEdgeDistanceType",
                                 {"EA0_EB0", "EA0_EB1", "EA1_EB0", "EA1_EB1", "EA_EB0", "EA_EB1",
                                  "EA0_EB", "EA1_EB", "EA_EB", "AUTO"});
  def_pair_functions(m, "distance_type", &point_edge_distance_type,
                     &point_triangle_distance_type, &edge_edge_distance_type);
}

// `<stem>_distance`, `_gradient` and `_hessian` of one typed family (dtype defaults to AUTO).
template <int NV, class Type, class Derivatives, std::size_t... I>
void def_distance_family(py::module_& m, const std::string& stem, Derivatives derivatives,
                         const std::array<const char*, NV>& names, std::index_sequence<I...>) {
  using Grad = Eigen::Matrix<double, 3 * NV, 1>;
  using Hess = Eigen::Matrix<double, 3 * NV, 3 * NV>;
  const py::arg_v dtype = py::arg("dtype") = Type::AUTO;
  m.def((stem + "_distance").c_str(),
        [derivatives](V3<I>... x, Type t) {
          check_points("distance", x...);
          return derivatives(x..., t, 0).d2;
        },
        py::arg(names[I])..., dtype, "Squared distance.");
  m.def((stem + "_distance_gradient").c_str(),
        [derivatives](V3<I>... x, Type t) {
          check_points("distance_gradient", x...);
          return Grad(derivatives(x..., t, 1).grad);
        },
        py::arg(names[I])..., dtype);
  m.def((stem + "_distance_hessian").c_str(),
        [derivatives](V3<I>... x, Type t) {
          check_points("distance_hessian", x...);
          return Hess(derivatives(x..., t, 2).hess);
        },
        py::arg(names[I])..., dtype);
}

void bind_distances(py::module_& m) {
  m.def("point_point_distance", &point_point_distance, py::arg("p0"), py::arg("p1"),
        "Squared distance |p0 − p1|².");
  m.def("point_point_distance_gradient",
        [](const Vec3& p0, const Vec3& p1) { return Vec6(point_point_distance_derivatives(p0, p1, 1).grad); },
        py::arg("p0"), py::arg("p1"));
  m.def("point_point_distance_hessian",
        [](const Vec3& p0, const Vec3& p1) { return Mat6(point_point_distance_derivatives(p0, p1, 2).hess); },
        py::arg("p0"), py::arg("p1"));
  def_distance_family<3, PointEdgeDistanceType>(m, "point_edge", &point_edge_distance_derivatives,
                                                {"p", "e0", "e1"}, std::make_index_sequence<3>());
  def_distance_family<4, PointTriangleDistanceType>(
      m, "point_triangle", &point_triangle_distance_derivatives, {"p", "t0", "t1", "t2"},
      std::make_index_sequence<4>());
  def_distance_family<4, EdgeEdgeDistanceType>(m, "edge_edge", &edge_edge_distance_derivatives,
                                               {"ea0", "ea1", "eb0", "eb1"},
                                               std::make_index_sequence<4>());
}

void bind_mollifier(py::module_& m) {
  m.def("edge_edge_mollifier_threshold", &edge_edge_mollifier_threshold, py::arg("ea0_rest"),
        py::arg("ea1_rest"), py::arg("eb0_rest"), py::arg("eb1_rest"),
        "ε_x = 1e-3 |ēa|²|ēb|² from the rest edges.");
  m.def("edge_edge_cross_squarednorm", &edge_edge_cross_squarednorm, py::arg("ea0"),
        py::arg("ea1"), py::arg("eb0"), py::arg("eb1"));
  m.def("edge_edge_cross_squarednorm_gradient", &edge_edge_cross_squarednorm_gradient,
        py::arg("ea0"), py::arg("ea1"), py::arg("eb0"), py::arg("eb1"));
  m.def("edge_edge_cross_squarednorm_hessian", &edge_edge_cross_squarednorm_hessian,
        py::arg("ea0"), py::arg("ea1"), py::arg("eb0"), py::arg("eb1"));
  m.def("edge_edge_mollifier",
        py::overload_cast<double, double>(&edge_edge_mollifier), py::arg("x"), py::arg("eps_x"),
        "m(c) for c = |ea × eb|².");
  m.def("edge_edge_mollifier_derivative", &edge_edge_mollifier_derivative, py::arg("x"),
        py::arg("eps_x"));
  m.def("edge_edge_mollifier_second_derivative", &edge_edge_mollifier_second_derivative,
        py::arg("x"), py::arg("eps_x"));
  m.def(
      "edge_edge_mollifier_derivatives",
      [](const Vec3& ea0, const Vec3& ea1, const Vec3& eb0, const Vec3& eb1, double eps_x) {
        const Mollifier r = edge_edge_mollifier_derivatives(ea0, ea1, eb0, eb1, eps_x, 2);
        return py::make_tuple(r.value, r.grad, r.hess);
      },
      py::arg("ea0"), py::arg("ea1"), py::arg("eb0"), py::arg("eb1"), py::arg("eps_x"),
      "(value, gradient[12], hessian[12x12]) of m(c(x)).");
}

void bind_barrier(py::module_& m) {
  m.def("barrier", &barrier, py::arg("d2"), py::arg("d_hat"), py::arg("xi") = 0.0,
        "b(d²) = −(d² − (d̂+ξ)²)² log((d² − ξ²)/(d̂² + 2d̂ξ)) (unit stiffness).");
  m.def("barrier_first_derivative", &barrier_first_derivative, py::arg("d2"), py::arg("d_hat"),
        py::arg("xi") = 0.0, "∂b/∂(d²).");
  m.def("barrier_second_derivative", &barrier_second_derivative, py::arg("d2"),
        py::arg("d_hat"), py::arg("xi") = 0.0, "∂²b/∂(d²)².");
  m.def("barrier_force_magnitude", &barrier_force_magnitude, py::arg("d2"), py::arg("d_hat"),
        py::arg("xi"), py::arg("kappa"), "λ = −∂(κ b)/∂d.");
  m.def("min_barrier_stiffness", &min_barrier_stiffness, py::arg("bbox_diagonal"),
        py::arg("d_hat"), py::arg("average_mass"), py::arg("dt"), py::arg("xi") = 0.0,
        py::arg("scale") = kBarrierStiffnessScale);
  m.def(
      "initial_barrier_stiffness",
      [](double diag, double d_hat, double mass, double dt, const VecX& grad_rest,
         const VecX& grad_barrier, double xi, double scale) {
        const BarrierStiffness s =
            initial_barrier_stiffness(diag, d_hat, mass, dt, grad_rest, grad_barrier, xi, scale);
        return py::make_tuple(s.kappa, s.kappa_min, s.kappa_max);
      },
      py::arg("bbox_diagonal"), py::arg("d_hat"), py::arg("average_mass"), py::arg("dt"),
      py::arg("grad_rest"), py::arg("grad_barrier"), py::arg("xi") = 0.0,
      py::arg("scale") = kBarrierStiffnessScale, "(kappa, kappa_min, kappa_max).");
  m.def("update_barrier_stiffness", &update_barrier_stiffness, py::arg("prev_min_gap"),
        py::arg("min_gap"), py::arg("kappa_max"), py::arg("kappa"), py::arg("bbox_diagonal"),
        py::arg("eps_scale") = 1e-9);
}

CcdOptions ccd_options(double min_distance, double tmax, double target, long max_iterations) {
  if (!(std::isfinite(min_distance) && min_distance >= 0.0))
    throw std::invalid_argument("CCD: min_distance must be finite and >= 0");
  if (!(std::isfinite(tmax) && tmax > 0.0))
    throw std::invalid_argument("CCD: tmax must be finite and > 0");
  if (!(target > 0.0 && target < 1.0))
    throw std::invalid_argument("CCD: target must lie in (0, 1)");
  if (max_iterations < 0) throw std::invalid_argument("CCD: max_iterations must be >= 0");
  CcdOptions o;
  o.min_distance = min_distance;
  o.tmax = tmax;
  o.target = target;
  o.max_iterations = max_iterations;
  return o;
}

// A CCD function of 2·NV points (start positions, then end positions) and the options.
template <class Fn, std::size_t... I>
void def_ccd(py::module_& m, const char* name, Fn fn, const std::array<const char*, sizeof...(I)>& names,
             std::index_sequence<I...>) {
  m.def(
      name,
      [fn](V3<I>... x, double min_distance, double tmax, double target, long max_iterations) {
        check_points("CCD", x...);
        return fn(x..., ccd_options(min_distance, tmax, target, max_iterations));
      },
      py::arg(names[I])..., py::arg("min_distance") = 0.0, py::arg("tmax") = 1.0,
      py::arg("target") = 0.1, py::arg("max_iterations") = 1000000L,
      "Conservative time of impact in [0, tmax] (tmax: no impact, 0: starts within "
      "min_distance).");
}

void bind_ccd(py::module_& m) {
  def_ccd(m, "point_point_ccd", &point_point_ccd, {"p0_t0", "p1_t0", "p0_t1", "p1_t1"},
          std::make_index_sequence<4>());
  def_ccd(m, "point_edge_ccd", &point_edge_ccd,
          {"p_t0", "e0_t0", "e1_t0", "p_t1", "e0_t1", "e1_t1"}, std::make_index_sequence<6>());
  def_ccd(m, "point_triangle_ccd", &point_triangle_ccd,
          {"p_t0", "t0_t0", "t1_t0", "t2_t0", "p_t1", "t0_t1", "t1_t1", "t2_t1"},
          std::make_index_sequence<8>());
  def_ccd(m, "edge_edge_ccd", &edge_edge_ccd,
          {"ea0_t0", "ea1_t0", "eb0_t0", "eb1_t0", "ea0_t1", "ea1_t1", "eb0_t1", "eb1_t1"},
          std::make_index_sequence<8>());
  m.def(
      "point_ground_ccd",
      [](const Vec3& p0, const Vec3& p1, double height, double min_distance, double tmax,
         double target) {
        check_points("point_ground_ccd", p0, p1);
        if (!std::isfinite(height))
          throw std::invalid_argument("point_ground_ccd: height must be finite");
        return point_ground_ccd(p0, p1, height, ccd_options(min_distance, tmax, target, 0));
      },
      py::arg("p_t0"), py::arg("p_t1"), py::arg("height"), py::arg("min_distance") = 0.0,
      py::arg("tmax") = 1.0, py::arg("target") = 0.1);
}

void bind_friction(py::module_& m) {
  m.def("smooth_friction_f0", &smooth_friction_f0, py::arg("y"), py::arg("eps"));
  m.def("smooth_friction_f1", &smooth_friction_f1, py::arg("y"), py::arg("eps"));
  m.def("smooth_friction_f2", &smooth_friction_f2, py::arg("y"), py::arg("eps"));
  m.def("smooth_friction_f1_over_x", &smooth_friction_f1_over_x, py::arg("y"), py::arg("eps"));
  m.def("smooth_friction_f2_x_minus_f1_over_x3", &smooth_friction_f2_x_minus_f1_over_x3,
        py::arg("y"), py::arg("eps"));

  m.def("point_point_tangent_basis", &point_point_tangent_basis, py::arg("p0"), py::arg("p1"));
  def_pair_functions(m, "tangent_basis", &point_edge_tangent_basis, &point_triangle_tangent_basis,
                     &edge_edge_tangent_basis);
  m.def("ground_tangent_basis", &ground_tangent_basis);

  def_pair_functions(m, "closest_point", &point_edge_closest_point,
                     &point_triangle_closest_point, &edge_edge_closest_point);

  m.def(
      "friction_potential",
      [](const VecX& dx, const VecX& weights, const Mat3x2& basis, double mu_lambda, double eps,
         bool majorize) {
        if (weights.size() < 1 || weights.size() > kMaxStencilVertices ||
            dx.size() != 3 * weights.size())
          throw std::invalid_argument("friction_potential: need 1..4 weights and 3 dx per weight");
        if (!(dx.allFinite() && weights.allFinite() && basis.allFinite() &&
              std::isfinite(mu_lambda) && std::isfinite(eps) && eps > 0.0))
          throw std::invalid_argument(
              "friction_potential: dx, weights, basis and mu_lambda must be finite, eps > 0");
        const FrictionDerivatives r =
            friction_potential(dx, weights, basis, mu_lambda, eps, 2, majorize);
        return py::make_tuple(r.value, VecX(r.grad), Eigen::MatrixXd(r.hess));
      },
      py::arg("dx"), py::arg("weights"), py::arg("basis"), py::arg("mu_lambda"), py::arg("eps"),
      py::arg("majorize") = false,
      "(value, gradient, hessian) of μλ f0(|Tᵀ Σ w_i Δx_i|) for one stencil (majorize: the "
      "Hessian of the quadratic model that bounds it from above).");
}

void bind_ground(py::module_& m) {
  m.def("point_ground_distance", &point_ground_distance, py::arg("p"), py::arg("height"),
        "(z − h)².");
  m.def("point_ground_distance_gradient", &point_ground_distance_gradient, py::arg("p"),
        py::arg("height"));
}

}  // namespace

void bind_contact_primitives(py::module_& m) {
  bind_distance_types(m);
  bind_distances(m);
  bind_mollifier(m);
  bind_barrier(m);
  bind_ccd(m);
  bind_friction(m);
  bind_ground(m);
}

}  // namespace abd::bindings
