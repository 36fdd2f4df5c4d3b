// Dyadic mass bindings: plain numpy arrays in, plain tuples/arrays out.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>
#include <stdexcept>

#include "bindings/bindings.h"
#include "mass/dyadic_mass.h"

namespace py = pybind11;

namespace abd::bindings {
namespace {
py::tuple as_tuple(const DyadicMass& d) { return py::make_tuple(d.m, d.m_x_bar, d.S); }
DyadicMass from_parts(double m, const Vec3& mx, const Mat3& S) {
  if (!(std::isfinite(m) && mx.allFinite() && S.allFinite()))
    throw std::invalid_argument("the dyadic mass (abd_mass, abd_mass_x_bar, "
                                "abd_mass_x_bar_x_bar) must be finite");
  DyadicMass d;
  d.m = m;
  d.m_x_bar = mx;
  d.S = S;
  return d;
}
}  // namespace

void bind_mass(py::module_& m) {
  m.def(
      "tet_mesh_mass",
      [](const MatX3& V, const MatX4i& T, double rho) { return as_tuple(tet_mesh_mass(V, T, rho)); },
      py::arg("vertices"), py::arg("tets"), py::arg("rho"),
      "Dyadic mass (m, m x̄, S) of a positively oriented tetrahedral mesh.");
  m.def(
      "closed_surface_mass",
      [](const MatX3& V, const MatX3i& F, double rho) {
        return as_tuple(closed_surface_mass(V, F, rho));
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("rho"),
      "Dyadic mass of a closed, outward-oriented surface treated as a solid.");
  m.def(
      "shell_mass",
      [](const MatX3& V, const MatX3i& F, const VecX& r, double rho) {
        return as_tuple(shell_mass(V, F, r, rho));
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("thickness"), py::arg("rho"),
      "Dyadic mass of a shell (slab of thickness 2r per triangle).");
  m.def(
      "rod_mass",
      [](const MatX3& V, const MatX2i& E, const VecX& r, double rho) {
        return as_tuple(rod_mass(V, E, r, rho));
      },
      py::arg("vertices"), py::arg("edges"), py::arg("thickness"), py::arg("rho"),
      "Dyadic mass of a rod (cylinder of radius r per segment).");
  m.def(
      "mass_matrix",
      [](double mass, const Vec3& mx, const Mat3& S) { return from_parts(mass, mx, S).matrix(); },
      py::arg("abd_mass"), py::arg("abd_mass_x_bar"), py::arg("abd_mass_x_bar_x_bar"),
      "The 12x12 ABD mass matrix built from the dyadic mass.");
  m.def(
      "to_rigid_body",
      [](double mass, const Vec3& mx, const Mat3& S) {
        const RigidBodyProperties rb = to_rigid_body(from_parts(mass, mx, S));
        return py::make_tuple(rb.mass, rb.center, rb.inertia);
      },
      py::arg("abd_mass"), py::arg("abd_mass_x_bar"), py::arg("abd_mass_x_bar_x_bar"));
  m.def(
      "from_rigid_body",
      [](double mass, const Vec3& c, const Mat3& I) { return as_tuple(from_rigid_body(mass, c, I)); },
      py::arg("mass"), py::arg("mass_center"), py::arg("inertia"));
}

}  // namespace abd::bindings
