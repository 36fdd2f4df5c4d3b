#include "bindings/bind_contact_parts.h"

namespace abd::bindings {
void bind_contact_term(pybind11::module_& /*m*/) {}
}  // namespace abd::bindings
