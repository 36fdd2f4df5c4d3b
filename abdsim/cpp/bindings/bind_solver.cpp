// Solver bindings (Scene data in, World stepping). Filled in by the dynamics work.
#include "bindings/bindings.h"

namespace abd::bindings {
void bind_solver(pybind11::module_& /*m*/) {}
}  // namespace abd::bindings
