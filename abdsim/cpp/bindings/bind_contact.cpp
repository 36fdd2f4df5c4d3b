// Contact bindings: `abdsim._core.contact` (distances, barrier, CCD, friction, the IPC
// contact energy term). Plain numpy arrays in, plain arrays out.
#include "bindings/bind_contact_parts.h"
#include "bindings/bindings.h"

namespace abd::bindings {
void bind_contact(pybind11::module_& m) {
  pybind11::module_ contact = m.def_submodule(
      "contact", "IPC contact: distances, barrier, additive CCD, lagged friction, energy term");
  bind_contact_primitives(contact);
  bind_contact_term(contact);
}
}  // namespace abd::bindings
