// Solver bindings: SceneData built from numpy arrays, the World stepper, its settings and
// diagnostics, and the EnergyTerm interface (C++ terms bind as subclasses of
// _core.EnergyTerm with a std::shared_ptr holder; Python terms subclass
// _core.PythonEnergyTerm).
#include <pybind11/eigen.h>

#include <Eigen/SVD>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "bindings/bindings.h"
#include "bindings/checked_property.h"
#include "contact/ipc_contact_term.h"
#include "solver/constrained_solve.h"
#include "solver/energy_term.h"
#include "solver/shape_energy_term.h"
#include "solver/world.h"

namespace py = pybind11;

namespace abd::bindings {
namespace {

using MatX12 = Eigen::Matrix<double, Eigen::Dynamic, 12, Eigen::RowMajor>;
using VecXi = Eigen::VectorXi;
using HessianBlocks = std::vector<std::tuple<int, int, Mat12>>;

MatX12 as_rows(const VecX& v) {
  return Eigen::Map<const MatX12>(v.data(), v.size() / 12, 12);
}

VecX as_stacked(const MatX12& m, Eigen::Index n_bodies, const char* what) {
  if (m.rows() != n_bodies)
    throw std::invalid_argument(std::string(what) + " must have shape (" +
                                std::to_string(n_bodies) + ", 12)");
  VecX v(12 * m.rows());
  Eigen::Map<MatX12>(v.data(), m.rows(), 12) = m;
  return v;
}

// Every index of a geometry is checked here, where it enters from Python: the solver and the
// contact code index vertices with them.
template <class Cells>
void check_cells(const Cells& C, Eigen::Index nv, const char* what) {
  for (Eigen::Index c = 0; c < C.rows(); ++c)
    for (Eigen::Index k = 0; k < C.cols(); ++k)
      if (C(c, k) < 0 || C(c, k) >= nv)
        throw std::out_of_range(std::string("add_geometry: ") + what + " " + std::to_string(c) +
                                " has vertex index " + std::to_string(C(c, k)) +
                                " out of range [0, " + std::to_string(nv) + ")");
}

void check_geometry(const MatX3& vertices, const MatX3i& triangles, const MatX2i& edges,
                    const VecX& thickness, int dim) {
  if (vertices.rows() == 0) throw std::invalid_argument("add_geometry: no vertices");
  for (Eigen::Index i = 0; i < vertices.rows(); ++i)
    if (!vertices.row(i).allFinite())
      throw std::invalid_argument("add_geometry: vertex " + std::to_string(i) +
                                  " has a NaN or infinite coordinate");
  if (thickness.size() != vertices.rows())
    throw std::invalid_argument("add_geometry: thickness must have one value per vertex (" +
                                std::to_string(vertices.rows()) + "), got " +
                                std::to_string(thickness.size()));
  for (Eigen::Index i = 0; i < thickness.size(); ++i)
    if (!(std::isfinite(thickness[i]) && thickness[i] >= 0.0))
      throw std::invalid_argument("add_geometry: thickness of vertex " + std::to_string(i) +
                                  " must be finite and >= 0");
  check_cells(triangles, vertices.rows(), "triangle");
  check_cells(edges, vertices.rows(), "edge");
  if (dim < 1 || dim > 3) throw std::invalid_argument("add_geometry: dim must be 1, 2 or 3");
}

// The 3x3 part A of a body state [p, a1, a2, a3] must be finite, proper (det A > 0: a mirror
// turns the body inside out) and non-degenerate (condition number < 1e6).
void check_affine(const Eigen::Ref<const Vec12>& q, const std::string& what) {
  if (!q.allFinite()) throw std::invalid_argument(what + " is not finite");
  Mat3 A;
  for (int i = 0; i < 3; ++i) A.row(i) = q.segment<3>(3 + 3 * i).transpose();
  const Vec3 sv = Eigen::JacobiSVD<Mat3>(A).singularValues();
  if (!(sv[2] > 1e-6 * sv[0]))
    throw std::invalid_argument(what + ": its 3x3 part A is degenerate (singular values " +
                                std::to_string(sv[0]) + ", " + std::to_string(sv[1]) + ", " +
                                std::to_string(sv[2]) + ")");
  if (!(A.determinant() > 0.0))
    throw std::invalid_argument(what + ": its 3x3 part A has det " +
                                std::to_string(A.determinant()) +
                                " <= 0 (a mirror); it must be proper");
}

void check_affine_rows(const MatX12& q, const std::string& what) {
  for (Eigen::Index i = 0; i < q.rows(); ++i)
    check_affine(q.row(i).transpose(), what + " of body " + std::to_string(i));
}

// An energy term written in Python: override name(), value(q), gradient(q) (12n array),
// hessian(q) (list of (row, col, 12x12) blocks, every coupling with its transpose) and
// optionally max_step(q, dq), begin_step(dt, q_t, q_dot_t), update(q). Values are
// unscaled potentials; the solver scales them.
//
// A term constructed with `bodies` says it involves only those bodies: it then splits by
// body as one element (EnergyTerm::splits_by_body), so the solver couples only the named
// bodies (one island) and every other body keeps its own per-body solve. Without it the
// term may involve any body, which couples all of them into one system. Its gradient and
// Hessian must then stay on the named bodies (checked: an entry elsewhere throws).
class PythonEnergyTerm : public EnergyTerm {
 public:
  PythonEnergyTerm() = default;
  explicit PythonEnergyTerm(std::vector<int> bodies) : bodies_(std::move(bodies)) {
    if (bodies_.empty()) throw std::invalid_argument("PythonEnergyTerm: bodies is empty");
    std::vector<int> sorted = bodies_;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t k = 0; k < sorted.size(); ++k) {
      if (sorted[k] < 0)
        throw std::invalid_argument("PythonEnergyTerm: body " + std::to_string(sorted[k]) +
                                    " is negative");
      if (k > 0 && sorted[k] == sorted[k - 1])
        throw std::invalid_argument("PythonEnergyTerm: body " + std::to_string(sorted[k]) +
                                    " is named twice");
    }
    named_ = std::move(sorted);
  }
  const std::vector<int>& bodies() const { return bodies_; }

  virtual VecX gradient(const VecX& q) const = 0;
  virtual HessianBlocks hessian(const VecX& q) const = 0;
  virtual void begin_step_py(double /*dt*/, const VecX& /*q_t*/, const VecX& /*q_dot_t*/) {}

  void begin_step(const StepContext& ctx) override { begin_step_py(ctx.dt, ctx.q_t, ctx.q_dot_t); }
  void add_gradient(const VecX& q, double scale, VecX& g) const override {
    const VecX mine = gradient(q);
    if (mine.size() != g.size())
      throw std::invalid_argument(name() + ".gradient returned " + std::to_string(mine.size()) +
                                  " values, expected " + std::to_string(g.size()));
    if (!named_.empty()) {
      check_range(g.size() / 12);
      for (Eigen::Index b = 0; b < g.size() / 12; ++b)
        if (!named(static_cast<int>(b)) && !mine.segment<12>(12 * b).isZero(0.0))
          throw std::invalid_argument(name() + ".gradient is non-zero on body " +
                                      std::to_string(b) + ", which is not in its bodies");
    }
    g += scale * mine;
  }
  void add_hessian(const VecX& q, double scale, std::vector<BodyBlock>& blocks) const override {
    for (const auto& [row, col, H] : hessian(q)) {
      if (!named_.empty() && (!named(row) || !named(col)))
        throw std::invalid_argument(name() + ".hessian returned block (" + std::to_string(row) +
                                    ", " + std::to_string(col) + "), outside its bodies");
      blocks.push_back({row, col, scale * H});
    }
  }

  // Splitting by body: the whole term is one element involving the named bodies.
  bool splits_by_body() const override { return !named_.empty(); }
  void add_body_values(const VecX& q, const std::vector<unsigned char>& movable, VecX& per_body,
                       std::vector<BodyLink>& links) const override {
    check_range(per_body.size());
    const int owner = first_in(movable);
    if (owner < 0) return;  // nothing it involves moves: a constant
    per_body[owner] += value(q);
    link(movable, links);
  }
  void body_links(const std::vector<unsigned char>& movable,
                  std::vector<BodyLink>& links) const override {
    link(movable, links);
  }
  void body_max_steps(const VecX& q, const VecX& dq, const std::vector<unsigned char>& movable,
                      VecX& bound, std::vector<unsigned char>& near,
                      std::vector<BodyLink>& links) const override {
    check_range(bound.size());
    if (first_in(movable) < 0) return;
    const double alpha = max_step(q, dq);
    for (int b : named_) {
      if (!movable[b]) continue;
      bound[b] = std::min(bound[b], alpha);
      near[b] = 1;  // its energy is not known to vanish anywhere
    }
    link(movable, links);
  }
  void mark_forced_bodies(std::vector<unsigned char>& flags) const override {
    if (named_.empty()) return EnergyTerm::mark_forced_bodies(flags);  // any body
    check_range(Eigen::Index(flags.size()));
    for (int b : named_) flags[size_t(b)] = 1;
  }

 private:
  bool named(int b) const { return std::binary_search(named_.begin(), named_.end(), b); }
  void check_range(Eigen::Index n_bodies) const {
    if (!named_.empty() && named_.back() >= n_bodies)
      throw std::invalid_argument(name() + ": body " + std::to_string(named_.back()) +
                                  " is out of range (the world has " +
                                  std::to_string(n_bodies) + " bodies)");
  }
  int first_in(const std::vector<unsigned char>& movable) const {
    for (int b : named_)
      if (movable[b]) return b;
    return -1;
  }
  // The movable named bodies in a chain: one island.
  void link(const std::vector<unsigned char>& movable, std::vector<BodyLink>& links) const {
    int previous = -1;
    for (int b : named_) {
      if (!movable[b]) continue;
      if (previous >= 0) links.push_back({previous, b});
      previous = b;
    }
  }

  std::vector<int> bodies_;  // as given
  std::vector<int> named_;   // sorted
};

class PythonEnergyTermTrampoline : public PythonEnergyTerm {
 public:
  using PythonEnergyTerm::PythonEnergyTerm;
  std::string name() const override {
    PYBIND11_OVERRIDE_PURE(std::string, PythonEnergyTerm, name, );
  }
  double value(const VecX& q) const override {
    PYBIND11_OVERRIDE_PURE(double, PythonEnergyTerm, value, q);
  }
  VecX gradient(const VecX& q) const override {
    PYBIND11_OVERRIDE_PURE(VecX, PythonEnergyTerm, gradient, q);
  }
  HessianBlocks hessian(const VecX& q) const override {
    PYBIND11_OVERRIDE_PURE(HessianBlocks, PythonEnergyTerm, hessian, q);
  }
  double max_step(const VecX& q, const VecX& dq) const override {
    PYBIND11_OVERRIDE(double, PythonEnergyTerm, max_step, q, dq);
  }
  void update(const VecX& q) override { PYBIND11_OVERRIDE(void, PythonEnergyTerm, update, q); }
  void begin_step_py(double dt, const VecX& q_t, const VecX& q_dot_t) override {
    PYBIND11_OVERRIDE_NAME(void, PythonEnergyTerm, "begin_step", begin_step_py, dt, q_t, q_dot_t);
  }
};

void bind_scene_data(py::module_& m) {
  py::class_<GeometryData>(m, "GeometryData", "Rest geometry shared by a geometry's bodies.")
      .def_readonly("rest_vertices", &GeometryData::rest_vertices)
      .def_readonly("triangles", &GeometryData::triangles)
      .def_readonly("edges", &GeometryData::edges)
      .def_readonly("thickness", &GeometryData::thickness)
      .def_readonly("self_collision", &GeometryData::self_collision)
      .def_readonly("dim", &GeometryData::dim);

  py::class_<BodyData>(m, "BodyData", "One affine body (an instance of a geometry).")
      .def_readonly("geometry", &BodyData::geometry)
      .def_readonly("q", &BodyData::q)
      .def_readonly("q_dot", &BodyData::q_dot)
      .def_readonly("mass", &BodyData::mass)
      .def_readonly("mass_x_bar", &BodyData::mass_x_bar)
      .def_readonly("mass_x_bar_x_bar", &BodyData::mass_x_bar_x_bar)
      .def_readonly("kappa", &BodyData::kappa)
      .def_readonly("volume", &BodyData::volume)
      .def_readonly("constitution_uid", &BodyData::constitution_uid)
      .def_readonly("is_fixed", &BodyData::is_fixed)
      .def_readonly("is_dynamic", &BodyData::is_dynamic)
      .def_readonly("external_kinetic", &BodyData::external_kinetic);

  py::class_<SceneData>(m, "SceneData",
                        "Plain scene data handed to the solver and the contact code.")
      .def(py::init<>())
      .def_readwrite("dt", &SceneData::dt)
      .def_readwrite("gravity", &SceneData::gravity)
      .def(
          "add_geometry",
          [](SceneData& s, const MatX3& vertices, const MatX3i& triangles, const MatX2i& edges,
             const VecX& thickness, int self_collision, int dim) {
            check_geometry(vertices, triangles, edges, thickness, dim);
            GeometryData g;
            g.rest_vertices = vertices;
            g.triangles = triangles;
            g.edges = edges;
            g.thickness = thickness;
            g.self_collision = self_collision;
            g.dim = dim;
            s.geometries.push_back(std::move(g));
            return static_cast<int>(s.geometries.size()) - 1;
          },
          py::arg("rest_vertices"), py::arg("triangles"), py::arg("edges"), py::arg("thickness"),
          py::arg("self_collision") = 0, py::arg("dim") = 3,
          "Adds a rest geometry; returns its index.")
      .def(
          "add_bodies",
          [](SceneData& s, int geometry, const MatX12& q, const MatX12& q_dot, double mass,
             const Vec3& mass_x_bar, const Mat3& mass_x_bar_x_bar, const VecX& kappa,
             double volume, int constitution_uid, const VecXi& is_fixed,
             const VecXi& is_dynamic, const VecXi& external_kinetic) {
            if (geometry < 0 || geometry >= static_cast<int>(s.geometries.size()))
              throw std::out_of_range("add_bodies: geometry index " + std::to_string(geometry) +
                                      " out of range [0, " +
                                      std::to_string(s.geometries.size()) + ")");
            const Eigen::Index k = q.rows();
            check_affine_rows(q, "add_bodies: q");
            if (q_dot.rows() != k || kappa.size() != k || is_fixed.size() != k ||
                is_dynamic.size() != k || external_kinetic.size() != k)
              throw std::invalid_argument(
                  "add_bodies: q, q_dot, kappa and the flags need one row per body");
            const int first = static_cast<int>(s.bodies.size());
            for (Eigen::Index i = 0; i < k; ++i) {
              BodyData b;
              b.geometry = geometry;
              b.q = q.row(i).transpose();
              b.q_dot = q_dot.row(i).transpose();
              b.mass = mass;
              b.mass_x_bar = mass_x_bar;
              b.mass_x_bar_x_bar = mass_x_bar_x_bar;
              b.kappa = kappa[i];
              b.volume = volume;
              b.constitution_uid = constitution_uid;
              b.is_fixed = is_fixed[i] != 0;
              b.is_dynamic = is_dynamic[i] != 0;
              b.external_kinetic = external_kinetic[i] != 0;
              s.bodies.push_back(b);
            }
            return first;
          },
          py::arg("geometry"), py::arg("q"), py::arg("q_dot"), py::arg("mass"),
          py::arg("mass_x_bar"), py::arg("mass_x_bar_x_bar"), py::arg("kappa"),
          py::arg("volume"), py::arg("constitution_uid"), py::arg("is_fixed"),
          py::arg("is_dynamic"), py::arg("external_kinetic"),
          "Adds k bodies of one geometry (q, q_dot: (k, 12)); returns the first body index.")
      .def_property_readonly("num_bodies",
                             [](const SceneData& s) { return static_cast<int>(s.bodies.size()); })
      .def_property_readonly(
          "num_geometries", [](const SceneData& s) { return static_cast<int>(s.geometries.size()); })
      .def(
          "geometry", [](const SceneData& s, int i) -> const GeometryData& { return s.geometries.at(i); },
          py::return_value_policy::reference_internal)
      .def(
          "body", [](const SceneData& s, int i) -> const BodyData& { return s.bodies.at(i); },
          py::return_value_policy::reference_internal);
}

// q handed to a term from Python: 12 finite values per body (the C++ terms index it by body).
const VecX& checked_q(const EnergyTerm& t, const VecX& q, const char* what = "q") {
  if (q.size() % 12 != 0)
    throw std::invalid_argument(std::string(what) + " must hold 12 values per body, got " +
                                std::to_string(q.size()));
  if (const auto* shape = dynamic_cast<const ShapeEnergyTerm*>(&t))
    if (q.size() != 12 * Eigen::Index(shape->num_bodies()))
      throw std::invalid_argument(std::string(what) + " must hold 12 x " +
                                  std::to_string(shape->num_bodies()) + " values, got " +
                                  std::to_string(q.size()));
  if (!q.allFinite()) throw std::invalid_argument(std::string(what) + " is not finite");
  return q;
}

void bind_terms(py::module_& m) {
  py::class_<EnergyTerm, std::shared_ptr<EnergyTerm>>(
      m, "EnergyTerm", "A potential in the incremental potential Π (unscaled).")
      .def("name", &EnergyTerm::name)
      .def("value", [](const EnergyTerm& t, const VecX& q) { return t.value(checked_q(t, q)); },
           py::arg("q"))
      .def(
          "gradient",
          [](const EnergyTerm& t, const VecX& q) {
            VecX g = VecX::Zero(q.size());
            t.add_gradient(checked_q(t, q), 1.0, g);
            return g;
          },
          py::arg("q"))
      .def(
          "hessian",
          [](const EnergyTerm& t, const VecX& q) {
            std::vector<BodyBlock> blocks;
            t.add_hessian(checked_q(t, q), 1.0, blocks);
            HessianBlocks out;
            out.reserve(blocks.size());
            for (const BodyBlock& b : blocks) out.emplace_back(b.row, b.col, b.H);
            return out;
          },
          py::arg("q"), "List of (row_body, col_body, 12x12 block).")
      .def(
          "max_step",
          [](const EnergyTerm& t, const VecX& q, const VecX& dq) {
            checked_q(t, dq, "dq");
            if (dq.size() != q.size()) throw std::invalid_argument("dq must have the size of q");
            return t.max_step(checked_q(t, q), dq);
          },
          py::arg("q"), py::arg("dq"));

  py::class_<PythonEnergyTerm, EnergyTerm, PythonEnergyTermTrampoline,
             std::shared_ptr<PythonEnergyTerm>>(m, "PythonEnergyTerm",
                                                "Base class for energy terms written in Python.")
      .def(py::init<>())
      .def(py::init<std::vector<int>>(), py::arg("bodies"),
           "A term involving only `bodies`: the solver couples just those (see the C++ "
           "docstring of PythonEnergyTerm); gradient and Hessian must stay on them.")
      .def_property_readonly("bodies", &PythonEnergyTerm::bodies,
                             "The bodies given at construction (empty: any body).")
      .def("gradient", &PythonEnergyTerm::gradient, py::arg("q"))
      .def("hessian", &PythonEnergyTerm::hessian, py::arg("q"))
      .def("max_step", &PythonEnergyTerm::max_step, py::arg("q"), py::arg("dq"))
      .def("update", &PythonEnergyTerm::update, py::arg("q"))
      .def("begin_step", &PythonEnergyTerm::begin_step_py, py::arg("dt"), py::arg("q_t"),
           py::arg("q_dot_t"));

  py::class_<ShapeEnergyTerm, EnergyTerm, std::shared_ptr<ShapeEnergyTerm>>(
      m, "ShapeEnergyTerm", "Σ κ v̄ Ψ(A) over the bodies of a SceneData.")
      .def(py::init<const SceneData&, bool>(), py::arg("scene"), py::arg("project_psd") = true);
}

void bind_settings(py::module_& m) {
  py::enum_<Integrator>(m, "Integrator")
      .value("BDF1", Integrator::kBDF1)
      .value("BDF2", Integrator::kBDF2);
  py::enum_<LinearSolverKind>(m, "LinearSolver")
      .value("AUTO", LinearSolverKind::kAuto)
      .value("DIRECT", LinearSolverKind::kDirect)
      .value("PCG", LinearSolverKind::kPCG);

  py::class_<SolverSettings> settings(m, "SolverSettings",
                                      "Settings of the implicit time stepper.");
  const char* type = "SolverSettings";
  def_finite(settings, type, "tol_translation", &SolverSettings::tol_translation);
  def_finite(settings, type, "tol_affine", &SolverSettings::tol_affine);
  def_finite(settings, type, "armijo_c", &SolverSettings::armijo_c);
  def_finite(settings, type, "ccd_safety", &SolverSettings::ccd_safety);
  def_finite(settings, type, "pcg_tolerance", &SolverSettings::pcg_tolerance);
  def_finite(settings, type, "kinematic_drive_stiffness",
             &SolverSettings::kinematic_drive_stiffness);
  settings.def(py::init<>())
      .def_readwrite("integrator", &SolverSettings::integrator)
      .def_readwrite("max_newton_iterations", &SolverSettings::max_newton_iterations)
      .def_readwrite("friction_iterations", &SolverSettings::friction_iterations)
      .def_readwrite("max_line_search_iterations", &SolverSettings::max_line_search_iterations)
      .def_readwrite("linear_solver", &SolverSettings::linear_solver)
      .def_readwrite("direct_max_dofs", &SolverSettings::direct_max_dofs)
      .def_readwrite("pcg_max_iterations", &SolverSettings::pcg_max_iterations)
      .def_readwrite("project_psd", &SolverSettings::project_psd)
      .def_readwrite("energies", &SolverSettings::energies)
      .def_readwrite("num_threads", &SolverSettings::num_threads);

  py::class_<StepDiagnostics>(m, "StepDiagnostics", "What one time step did.")
      .def_readonly("step", &StepDiagnostics::step)
      .def_readonly("time", &StepDiagnostics::time)
      .def_readonly("newton_iterations", &StepDiagnostics::newton_iterations)
      .def_readonly("total_body_iterations", &StepDiagnostics::total_body_iterations)
      .def_readonly("converged", &StepDiagnostics::converged)
      .def_readonly("step_translation", &StepDiagnostics::step_translation)
      .def_readonly("step_affine", &StepDiagnostics::step_affine)
      .def_readonly("residual", &StepDiagnostics::residual)
      .def_readonly("line_search_alphas", &StepDiagnostics::line_search_alphas)
      .def_readonly("min_term_max_step", &StepDiagnostics::min_term_max_step)
      .def_readonly("energies", &StepDiagnostics::energies)
      .def_readonly("coupled_bodies", &StepDiagnostics::coupled_bodies)
      .def_readonly("islands", &StepDiagnostics::islands)
      .def_readonly("contact_point_triangle", &StepDiagnostics::contact_point_triangle)
      .def_readonly("contact_edge_edge", &StepDiagnostics::contact_edge_edge)
      .def_readonly("contact_point_ground", &StepDiagnostics::contact_point_ground)
      .def_readonly("contact_friction", &StepDiagnostics::contact_friction)
      .def_readonly("min_contact_distance", &StepDiagnostics::min_contact_distance)
      .def_readonly("contact_kappa", &StepDiagnostics::contact_kappa)
      .def_readonly("integrator_order", &StepDiagnostics::integrator_order)
      .def_readonly("restitution_impulses", &StepDiagnostics::restitution_impulses)
      .def_readonly("driven_bodies", &StepDiagnostics::driven_bodies)
      .def_readonly("kinematic_lag", &StepDiagnostics::kinematic_lag)
      .def_readonly("kinematic_lag_body", &StepDiagnostics::kinematic_lag_body)
      .def_readonly("substeps", &StepDiagnostics::substeps)
      .def_readonly("substep_reason", &StepDiagnostics::substep_reason)
      .def_readonly("discarded_newton_iterations", &StepDiagnostics::discarded_newton_iterations)
      .def_readonly("discarded_time", &StepDiagnostics::discarded_time)
      .def_readonly("joint_violation", &StepDiagnostics::joint_violation)
      .def_readonly("joint_violation_angle", &StepDiagnostics::joint_violation_angle)
      .def_readonly("linear_solver", &StepDiagnostics::linear_solver)
      .def_readonly("pcg_iterations", &StepDiagnostics::pcg_iterations)
      .def_readonly("wall_time", &StepDiagnostics::wall_time)
      .def_readonly("time_assembly", &StepDiagnostics::time_assembly)
      .def_readonly("time_linear_solve", &StepDiagnostics::time_linear_solve)
      .def_readonly("time_ccd", &StepDiagnostics::time_ccd)
      .def_readonly("time_line_search", &StepDiagnostics::time_line_search)
      .def_readonly("time_contact_update", &StepDiagnostics::time_contact_update)
      .def_readonly("time_broad_phase", &StepDiagnostics::time_broad_phase)
      .def_readonly("line_search_ccd_cuts", &StepDiagnostics::line_search_ccd_cuts)
      .def_readonly("line_search_halvings", &StepDiagnostics::line_search_halvings)
      .def_readonly("symbolic_analyses", &StepDiagnostics::symbolic_analyses);
}

void bind_world(py::module_& m) {
  py::class_<World>(m, "World", "The implicit ABD stepper (see abdsim.World for the Python API).")
      .def(py::init<const SceneData&, const SolverSettings&>(), py::arg("scene"),
           py::arg("settings") = SolverSettings())
      .def(
          "add_term", [](World& w, std::shared_ptr<EnergyTerm> t) { w.add_term(std::move(t)); },
          py::arg("term"), py::keep_alive<1, 2>())
      .def_property_readonly("terms", &World::terms)
      .def(
          "add_constraint",
          [](World& w, std::shared_ptr<Constraint> c) { w.add_constraint(std::move(c)); },
          py::arg("constraint"), py::keep_alive<1, 2>())
      .def(
          "enable_contact",
          [](World& w, const ContactSettings& settings) {
            w.enable_contact(settings);
            return w.contact();
          },
          py::arg("settings"),
          "Builds the IPC contact term from the scene, checks the current state (ValueError "
          "naming the bodies if surfaces intersect or are closer than their thickness), adds "
          "it; returns the term.")
      .def_property_readonly("contact", [](const World& w) { return w.contact(); },
                             "The contact term (None without contact).")
      .def("min_contact_distance", &World::min_contact_distance, py::arg("max_distance") = -1.0,
           "Smallest gap at the current state among pairs closer than max_distance (<= 0: "
           "d_hat); inf if none.")
      .def(
          "step",
          [](World& w, int n) {
            if (n < 0) throw std::invalid_argument("step count must be >= 0");
            py::gil_scoped_release release;
            for (int i = 0; i < n; ++i) w.step();
          },
          py::arg("n") = 1, "Advances n steps; raises SolverError (state kept) on failure.")
      .def_property_readonly("num_bodies", &World::num_bodies)
      .def_property_readonly("time", &World::time)
      .def_property_readonly("next_time", &World::next_time)
      .def("set_time", &World::set_time, py::arg("t"))
      .def_property_readonly("step_count", &World::step_count)
      .def_property_readonly("q", [](const World& w) { return as_rows(w.q()); },
                             "State (n_bodies, 12): [p, a1, a2, a3] per body.")
      .def_property_readonly("q_dot", [](const World& w) { return as_rows(w.q_dot()); })
      .def(
          "set_state",
          [](World& w, const MatX12& q, const MatX12& q_dot) {
            check_affine_rows(q, "set_state: q");
            w.set_state(as_stacked(q, w.num_bodies(), "q"),
                        as_stacked(q_dot, w.num_bodies(), "q_dot"));
          },
          py::arg("q"), py::arg("q_dot"))
      .def(
          "set_kinematic_target",
          [](World& w, int body, const Vec12& q) {
            check_affine(q, "kinematic target");
            w.set_kinematic_target(body, q);
          },
          py::arg("body"), py::arg("q_target"))
      .def(
          "set_kinematic_targets",
          [](World& w, const VecXi& bodies, const MatX12& q) {
            if (q.rows() != bodies.size())
              throw std::invalid_argument("set_kinematic_targets: one (12,) row per body");
            check_affine_rows(q, "kinematic target");
            for (Eigen::Index i = 0; i < bodies.size(); ++i)
              w.set_kinematic_target(bodies[i], q.row(i).transpose());
          },
          py::arg("bodies"), py::arg("q_targets"))
      .def("release_kinematic", &World::release_kinematic, py::arg("body"))
      .def("is_kinematic", &World::is_kinematic, py::arg("body"))
      .def("mass_matrix", &World::mass_matrix, py::arg("body"))
      // A copy: the World drops old steps' diagnostics as it goes, and a Python object
      // referring into them would outlive them.
      .def_property_readonly("diagnostics", [](const World& w) { return w.diagnostics(); })
      .def_property_readonly(
          "history",
          [](const World& w) {
            return std::vector<StepDiagnostics>(w.history().begin(), w.history().end());
          })
      .def("set_history_limit", &World::set_history_limit, py::arg("limit"))
      .def("clear_history", &World::clear_history)
      .def_property_readonly("scene", &World::scene, py::return_value_policy::reference_internal)
      .def_property_readonly("settings", &World::settings);
}

// The constrained Newton solve on its own (for tests against a dense reference): the
// matrix from its 12x12 blocks, the rows as (body_a, body_b, ja, jb, value) (body_b −1: the
// world), soft rows (rank-one Hessian parts k (ga ⊕ gb)(ga ⊕ gb)ᵀ) as (a, b, ga, gb, k).
// Returns the solution (n_bodies, 12) and the path taken ("tree" or "sparse").
void bind_kkt(py::module_& m) {
  using Row = std::tuple<int, int, Vec12, Vec12, double>;
  m.def(
      "solve_kkt",
      [](const std::vector<Mat12>& diagonal, const HessianBlocks& couplings,
         const std::vector<int>& fixed, const std::vector<Row>& rows, const MatX12& rhs,
         bool allow_tree, const std::vector<Row>& soft_rows) {
        const int n = static_cast<int>(diagonal.size());
        if (static_cast<int>(fixed.size()) != n || rhs.rows() != n)
          throw std::invalid_argument("solve_kkt: diagonal, fixed and rhs need one entry per body");
        std::vector<std::uint8_t> fixed_flags(fixed.begin(), fixed.end());
        BlockSystem system;
        system.reset(n, fixed_flags);
        for (int b = 0; b < n; ++b) system.diagonal(b) = fixed_flags[b] ? Mat12::Zero() : diagonal[b];
        std::vector<BodyBlock> blocks;
        for (const auto& [i, j, H] : couplings) {
          if (i < 0 || i >= n || j < 0 || j >= n || i == j)
            throw std::invalid_argument("solve_kkt: coupling between bodies out of range");
          blocks.push_back({i, j, H});
        }
        system.add_blocks(blocks);
        std::vector<HessianRow> hessian_rows;
        for (const auto& [a, b, ga, gb, k] : soft_rows) {
          if (!(std::isfinite(k) && k > 0.0))
            throw std::invalid_argument("solve_kkt: a soft row's k must be positive and finite");
          hessian_rows.push_back({a, b, ga, gb, k});
        }
        system.add_rows(hessian_rows, true);
        system.finalize();
        std::vector<ConstraintRow> constraint_rows;
        for (const auto& [a, b, ja, jb, value] : rows) {
          if (a < 0 || a >= n || b < -1 || b >= n)
            throw std::invalid_argument("solve_kkt: a row's body is out of range");
          constraint_rows.push_back({a, b, ja, jb, value});
        }
        VecX x;
        std::string path = "sparse";
        TreeKkt tree;
        const VecX b = as_stacked(rhs, n, "rhs");
        if (allow_tree && tree.solve(system, constraint_rows, b, x)) {
          path = "tree";
        } else {
          KktFactorisation kkt(false);
          kkt.solve(system, constraint_rows, b, x);
        }
        return std::make_pair(MatX12(as_rows(x)), path);
      },
      py::arg("diagonal"), py::arg("couplings"), py::arg("fixed"), py::arg("rows"), py::arg("rhs"),
      py::arg("allow_tree") = true, py::arg("soft_rows") = std::vector<Row>());
}

}  // namespace

void bind_solver(py::module_& m) {
  py::register_exception<SolverError>(m, "SolverError", PyExc_RuntimeError);
  bind_scene_data(m);
  bind_terms(m);
  bind_settings(m);
  bind_world(m);
  bind_kkt(m);
}

}  // namespace abd::bindings
