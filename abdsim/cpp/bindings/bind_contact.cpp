// Contact bindings (distances, barrier, CCD, friction). Filled in by the contact work.
#include "bindings/bindings.h"

namespace abd::bindings {
void bind_contact(pybind11::module_& /*m*/) {}
}  // namespace abd::bindings
