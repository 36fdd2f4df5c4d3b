// Shape-energy bindings, so users and tests can check values and derivatives.
#include <pybind11/eigen.h>

#include "bindings/bindings.h"
#include "energy/shape_energy.h"

namespace py = pybind11;

namespace abd::bindings {

void bind_energy(py::module_& m) {
  m.def(
      "shape_energy",
      [](int uid, const Vec12& q, double kappa, double volume, bool project_psd, double absorb) {
        const ShapeEnergyResult r = shape_energy(uid, q, kappa, volume, project_psd, true, absorb);
        return py::make_tuple(r.value, r.gradient, r.hessian);
      },
      py::arg("uid"), py::arg("q"), py::arg("kappa"), py::arg("volume"),
      py::arg("project_psd") = false, py::arg("absorb") = 0.0,
      "(value, gradient[12], hessian[12x12]) of the shape energy κ v̄ Ψ(A).");
}

}  // namespace abd::bindings
