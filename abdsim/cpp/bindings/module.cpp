#include "bindings/bindings.h"

#include <coal/config.hh>

PYBIND11_MODULE(_core, m) {
  m.doc() = "abdsim C++ core: dyadic mass, shape energies, implicit solver, IPC contact, joints";
  m.attr("coal_version") = COAL_VERSION;
  abd::bindings::bind_mass(m);
  abd::bindings::bind_energy(m);
  abd::bindings::bind_solver(m);
  abd::bindings::bind_contact(m);
  abd::bindings::bind_joints(m);
  abd::bindings::bind_block_system(m);
}
