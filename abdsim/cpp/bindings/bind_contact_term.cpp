// Bindings of the IPC contact energy term, built from plain arrays so it can be tested (and
// used) without the Python Scene: per geometry rest vertices / triangles / edges / thickness,
// per body its geometry index and state q.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <string>
#include <optional>

#include "bindings/bind_contact_parts.h"
#include "bindings/checked_property.h"
#include "contact/ipc_contact_term.h"

namespace py = pybind11;

namespace abd::bindings {
namespace {
using contact::StencilKind;

// q as (n, 12) or (12 n,) → the stacked VecX.
VecX flat_q(const py::array_t<double, py::array::c_style | py::array::forcecast>& q) {
  VecX out(q.size());
  std::copy(q.data(), q.data() + q.size(), out.data());
  // The term checks the size; NaN would reach the BVHs and the CCD.
  if (!out.allFinite()) throw std::invalid_argument("q contains NaN or infinite values");
  return out;
}

ContactRule to_rule(const py::handle& r) {
  if (py::isinstance<ContactRule>(r)) return r.cast<ContactRule>();
  const auto t = r.cast<py::tuple>();
  if (t.size() != 2 && t.size() != 3)
    throw std::invalid_argument("a contact rule is (enabled, mu) or (enabled, mu, damping)");
  return ContactRule{t[0].cast<bool>(), t[1].cast<double>(),
                     t.size() == 3 ? t[2].cast<double>() : -1.0};
}

py::dict body_max_steps_dict(const IpcContactTerm& t,
                             const py::array_t<double, py::array::c_style | py::array::forcecast>& q,
                             const py::array_t<double, py::array::c_style | py::array::forcecast>& dq) {
  const VecX qs = flat_q(q), dqs = flat_q(dq);
  const int n = t.mesh().num_bodies();
  std::vector<unsigned char> movable(static_cast<size_t>(n)), near(static_cast<size_t>(n), 0);
  for (int b = 0; b < n; ++b) movable[size_t(b)] = !t.mesh().fixed[b];
  VecX bound = VecX::Ones(n);
  std::vector<BodyLink> links;
  t.body_max_steps(qs, dqs, movable, bound, near, links);
  py::dict d;
  d["bound"] = bound;
  d["near"] = std::vector<bool>(near.begin(), near.end());
  py::list pairs;
  for (const BodyLink& l : links) pairs.append(py::make_tuple(l.a, l.b));
  d["links"] = pairs;
  d["candidates"] = t.swept_candidate_count();
  d["scale"] = t.swept_scale();
  return d;
}

std::shared_ptr<IpcContactTerm> make_term(
    const std::vector<MatX3>& vertices, const std::vector<MatX3i>& triangles,
    const std::vector<MatX2i>& edges, const std::vector<VecX>& thickness,
    const std::vector<int>& self_collision, const std::vector<int>& body_geometry,
    const py::array_t<double, py::array::c_style | py::array::forcecast>& q,
    const std::optional<std::vector<bool>>& is_fixed, const std::optional<std::vector<double>>& mass,
    const std::optional<ContactSettings>& settings, double dt) {
  const size_t ng = vertices.size();
  auto optional_size_ok = [ng](size_t n) { return n == 0 || n == ng; };
  if (!optional_size_ok(triangles.size()) || !optional_size_ok(edges.size()) ||
      !optional_size_ok(thickness.size()) || !optional_size_ok(self_collision.size()))
    throw std::invalid_argument("triangles, edges, thickness, self_collision: one per geometry");
  if (!(std::isfinite(dt) && dt > 0.0))
    throw std::invalid_argument("dt must be positive and finite");
  SceneData scene;
  scene.dt = dt;
  for (size_t g = 0; g < ng; ++g) {
    GeometryData geo;
    if (!vertices[g].allFinite())
      throw std::invalid_argument("geometry " + std::to_string(g) +
                                  ": vertices contain NaN or infinite values");
    if (!thickness.empty() && !thickness[g].allFinite())
      throw std::invalid_argument("geometry " + std::to_string(g) + ": thickness is not finite");
    geo.rest_vertices = vertices[g];
    if (!triangles.empty()) geo.triangles = triangles[g];
    if (!edges.empty()) geo.edges = edges[g];
    if (!thickness.empty()) geo.thickness = thickness[g];
    if (!self_collision.empty()) geo.self_collision = self_collision[g];
    scene.geometries.push_back(geo);
  }
  const VecX qs = flat_q(q);
  const size_t nb = body_geometry.size();
  if (qs.size() != 12 * Eigen::Index(nb)) throw std::invalid_argument("q must hold 12 values per body");
  if ((is_fixed && is_fixed->size() != nb) || (mass && mass->size() != nb))
    throw std::invalid_argument("is_fixed and mass: one value per body");
  for (size_t b = 0; b < nb; ++b) {
    BodyData body;
    body.geometry = body_geometry[b];
    body.q = qs.segment<12>(12 * b);
    body.q_dot.setZero();
    body.is_fixed = is_fixed && (*is_fixed)[b];
    body.mass = mass ? (*mass)[b] : 1.0;
    if (!(std::isfinite(body.mass) && body.mass > 0.0))
      throw std::invalid_argument("body " + std::to_string(b) +
                                  ": mass must be positive and finite");
    scene.bodies.push_back(body);
  }
  return std::make_shared<IpcContactTerm>(scene, settings.value_or(ContactSettings{}));
}

py::dict active_pairs(const IpcContactTerm& t) {
  std::vector<std::array<int, 2>> pt, ee;
  std::vector<int> ground;
  for (const auto& s : t.active_stencils()) {
    if (s.kind == StencilKind::PointTriangle) pt.push_back(s.primitives);
    if (s.kind == StencilKind::EdgeEdge) ee.push_back(s.primitives);
    if (s.kind == StencilKind::PointGround) ground.push_back(s.primitives[0]);
  }
  auto pairs = [](const std::vector<std::array<int, 2>>& v) {
    py::array_t<int> a({py::ssize_t(v.size()), py::ssize_t(2)});
    auto m = a.mutable_unchecked<2>();
    for (size_t i = 0; i < v.size(); ++i) m(i, 0) = v[i][0], m(i, 1) = v[i][1];
    return a;
  };
  py::dict d;
  d["point_triangle"] = pairs(pt);
  d["edge_edge"] = pairs(ee);
  d["point_ground"] = py::array_t<int>(py::ssize_t(ground.size()), ground.data());
  return d;
}

Eigen::MatrixXd dense_hessian(const IpcContactTerm& t, const VecX& q) {
  std::vector<BodyBlock> blocks;
  t.add_hessian(q, 1.0, blocks);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(q.size(), q.size());
  for (const BodyBlock& b : blocks) H.block<12, 12>(12 * b.row, 12 * b.col) += b.H;
  return H;
}

void bind_settings(py::module_& m) {
  py::class_<ContactRule>(m, "ContactRule")
      .def(py::init([](bool enabled, double mu, double damping, double restitution) {
             return ContactRule{enabled, mu, damping, restitution};
           }),
           py::arg("enabled") = true, py::arg("mu") = 0.5, py::arg("damping") = -1.0,
           py::arg("restitution") = -1.0)
      .def_readwrite("enabled", &ContactRule::enabled)
      .def_readwrite("mu", &ContactRule::mu)
      .def_readwrite("damping", &ContactRule::damping, "normal damping ratio; < 0: default")
      .def_readwrite("restitution", &ContactRule::restitution,
                     "coefficient of restitution; < 0: default");

  py::class_<ContactSettings> settings(m, "ContactSettings", "Settings of the IPC contact term.");
  const char* type = "ContactSettings";
  def_finite(settings, type, "d_hat", &ContactSettings::d_hat, "barrier activation distance (m)");
  def_finite(settings, type, "kappa", &ContactSettings::kappa, "contact stiffness; <= 0: adaptive");
  def_finite(settings, type, "mu", &ContactSettings::mu, "default friction coefficient");
  def_finite(settings, type, "eps_v", &ContactSettings::eps_v, "friction smoothing speed (m/s)");
  def_finite(settings, type, "ground_height", &ContactSettings::ground_height);
  def_finite(settings, type, "ccd_target", &ContactSettings::ccd_target);
  def_finite(settings, type, "damping", &ContactSettings::damping,
             "default normal damping ratio of every pair (0: none)");
  def_finite(settings, type, "restitution", &ContactSettings::restitution,
             "default coefficient of restitution of every pair (< 0: none)");
  def_finite(settings, type, "restitution_threshold", &ContactSettings::restitution_threshold,
             "approach speed (m/s) below which an impact is left to the integrator");
  settings.def(py::init<>())
      .def_readwrite("ground", &ContactSettings::ground)
      .def_readwrite("ground_contact_element", &ContactSettings::ground_contact_element)
      .def_readwrite("body_contact_element", &ContactSettings::body_contact_element)
      .def_readwrite("project_hessian", &ContactSettings::project_hessian)
      .def(
          "set_contact_table",
          [](ContactSettings& s, py::object rule) {
            if (rule.is_none()) {
              s.contact_table = nullptr;
              return;
            }
            // Called only while an IpcContactTerm is built, i.e. with the GIL held.
            s.contact_table = [rule](int a, int b) { return to_rule(rule(a, b)); };
          },
          py::arg("rule"),
          "rule(element_a, element_b) -> ContactRule or (enabled, mu); None: all collide.")
      .def(
          "set_contact_table_matrices",
          [](ContactSettings& s, const Eigen::MatrixXi& enabled, const Eigen::MatrixXd& mu,
             const std::optional<Eigen::MatrixXd>& damping,
             const std::optional<Eigen::MatrixXd>& restitution) {
            s.contact_table = contact::contact_rule_from_matrices(
                enabled, mu, s.mu, damping.value_or(Eigen::MatrixXd()),
                restitution.value_or(Eigen::MatrixXd()));
          },
          py::arg("enabled"), py::arg("mu"), py::arg("damping") = py::none(),
          py::arg("restitution") = py::none());
}

}  // namespace

void bind_contact_term(py::module_& m) {
  bind_settings(m);
  using Q = const py::array_t<double, py::array::c_style | py::array::forcecast>&;
  py::class_<IpcContactTerm, EnergyTerm, std::shared_ptr<IpcContactTerm>>(m, "IpcContactTerm",
                             "IPC barrier + lagged friction between affine bodies and the ground.")
      .def(py::init(&make_term), py::arg("vertices"), py::arg("triangles"), py::arg("edges"),
           py::arg("thickness"), py::arg("self_collision"), py::arg("body_geometry"),
           py::arg("q"), py::arg("is_fixed") = py::none(), py::arg("mass") = py::none(),
           py::arg("settings") = py::none(), py::arg("dt") = 0.01,
           "Per geometry: vertices (nv, 3), triangles (nf, 3), edges (ne, 2; [] derives them "
           "from the triangles), thickness (nv,) or [] for all 0, self_collision flag. "
           "Per body: geometry index and q (n, 12).")
      .def_property_readonly("name", &IpcContactTerm::name)
      .def("update", [](IpcContactTerm& t, Q q) { t.update(flat_q(q)); }, py::arg("q"))
      .def(
          "begin_step",
          [](IpcContactTerm& t, Q q_t, double dt) {
            const VecX q = flat_q(q_t);
            const VecX q_dot = VecX::Zero(q.size());
            t.begin_step(StepContext{dt, q, q_dot, 0.0, nullptr, std::nullopt});
          },
          py::arg("q_t"), py::arg("dt"))
      .def("value", [](const IpcContactTerm& t, Q q) { return t.value(flat_q(q)); }, py::arg("q"))
      .def("barrier_value", [](const IpcContactTerm& t, Q q) { return t.barrier_value(flat_q(q)); },
           py::arg("q"))
      .def("friction_value",
           [](const IpcContactTerm& t, Q q) { return t.friction_value(flat_q(q)); }, py::arg("q"))
      .def("damping_value",
           [](const IpcContactTerm& t, Q q) { return t.damping_value(flat_q(q)); }, py::arg("q"))
      .def(
          "gradient",
          [](const IpcContactTerm& t, Q q) {
            const VecX qs = flat_q(q);
            VecX g = VecX::Zero(qs.size());
            t.add_gradient(qs, 1.0, g);
            return g;
          },
          py::arg("q"))
      .def("hessian", [](const IpcContactTerm& t, Q q) { return dense_hessian(t, flat_q(q)); },
           py::arg("q"), "Dense (12n, 12n) PSD Hessian (for tests).")
      .def(
          "hessian_blocks",
          [](const IpcContactTerm& t, Q q) {
            std::vector<BodyBlock> blocks;
            t.add_hessian(flat_q(q), 1.0, blocks);
            py::list out;
            for (const auto& b : blocks) out.append(py::make_tuple(b.row, b.col, Mat12(b.H)));
            return out;
          },
          py::arg("q"), "[(row body, column body, 12x12 block)].")
      .def("max_step", [](const IpcContactTerm& t, Q q, Q dq) { return t.max_step(flat_q(q), flat_q(dq)); },
           py::arg("q"), py::arg("dq"))
      .def("body_max_steps", &body_max_steps_dict, py::arg("q"), py::arg("dq"),
           "Per-body step bounds of the move q -> q + dq (every non-fixed body movable): dict "
           "of bound (n,), near (n,), links [(a, b)], candidates (kept by the sweep) and "
           "scale (n,): the share of dq each body's checked move took.")
      .def_property("max_candidates", &IpcContactTerm::max_candidates,
                    &IpcContactTerm::set_max_candidates,
                    "the most candidate pairs one broad-phase query may collect")
      .def("min_distance",
           [](const IpcContactTerm& t, Q q, double max_distance) {
             return t.min_distance(flat_q(q), max_distance);
           },
           py::arg("q"), py::arg("max_distance") = -1.0)
      .def("line_crosses",
           [](const IpcContactTerm& t, Q q, Q dq, int restarts, double touching) {
             return t.line_crosses(flat_q(q), flat_q(dq), restarts, touching);
           },
           py::arg("q"), py::arg("dq"), py::arg("restarts") = 16, py::arg("touching") = 0.0,
           "True when the straight line q -> q + dq brings a pair into contact (each pair's "
           "CCD restarted where it stopped, at most `restarts` times; a pair that restarts "
           "from a gap <= touching touches, whatever its CCD answers from there).")
      .def("check_initial", [](const IpcContactTerm& t, Q q) { t.check_initial(flat_q(q)); },
           py::arg("q"), "Raises ValueError naming the bodies if q is not a valid start.")
      .def_property("kappa", &IpcContactTerm::kappa, &IpcContactTerm::set_kappa)
      .def_property_readonly("adaptive_kappa", &IpcContactTerm::adaptive_kappa)
      .def(
          "initialize_kappa",
          [](IpcContactTerm& t, Q q, const VecX& grad_rest) {
            return t.initialize_kappa(flat_q(q), grad_rest);
          },
          py::arg("q"), py::arg("grad_rest"))
      .def("stiffness_bounds",
           [](const IpcContactTerm& t) {
             const auto s = t.stiffness_bounds();
             return py::make_tuple(s.kappa, s.kappa_min, s.kappa_max);
           },
           "(kappa, kappa_min, kappa_max)")
      .def("counts",
           [](const IpcContactTerm& t) {
             const ContactCounts c = t.counts();
             py::dict d;
             d["point_triangle"] = c.point_triangle;
             d["edge_edge"] = c.edge_edge;
             d["point_ground"] = c.point_ground;
             d["friction"] = c.friction;
             d["damping"] = c.damping;
             return d;
           })
      .def("active_pairs", &active_pairs,
           "Active stencils of the last update(): global (vertex, face), (edge, edge), vertex.")
      .def("world_vertices",
           [](const IpcContactTerm& t, Q q) {
             const std::vector<Vec3> x = t.mesh().world_vertices(flat_q(q));
             MatX3 out(x.size(), 3);
             for (size_t i = 0; i < x.size(); ++i) out.row(i) = x[i].transpose();
             return out;
           },
           py::arg("q"))
      .def_property_readonly("vertex_offsets", [](const IpcContactTerm& t) { return t.mesh().vertex_offset; })
      .def_property_readonly("edge_offsets", [](const IpcContactTerm& t) { return t.mesh().edge_offset; })
      .def_property_readonly("face_offsets", [](const IpcContactTerm& t) { return t.mesh().face_offset; })
      .def_property_readonly("edges", [](const IpcContactTerm& t) { return t.mesh().edges; })
      .def_property_readonly("faces", [](const IpcContactTerm& t) { return t.mesh().faces; })
      .def_property_readonly("bbox_diagonal", &IpcContactTerm::bbox_diagonal)
      .def_property_readonly("stiffness_length", &IpcContactTerm::stiffness_length,
                             "the length κ_min is measured against (1e3 d̂; IPC's bbox diagonal)")
      .def("contact_forces", &contact_forces_arrays, py::arg("q"),
           "Forces at q (12 n,) per pair: dict of bodies (k, 2; -1 the ground), points, "
           "normals (from the second side to the first), normal_force (k,), friction_force "
           "(k, 3; on the first side).")
      .def("contact_wrenches", &contact_wrenches_array, py::arg("q"), py::arg("centers"),
           "Net contact force and torque about centers (n, 3, world) per body: (n, 6).");
}

}  // namespace abd::bindings
