// The contact submodule is bound in parts, one translation unit each (bind_contact.cpp
// creates `abdsim._core.contact` and calls them).
#pragma once
#include <pybind11/pybind11.h>

#include "contact/ipc_contact_term.h"

namespace abd::bindings {
void bind_contact_primitives(pybind11::module_& m);  // distances, barrier, CCD, friction
void bind_contact_term(pybind11::module_& m);        // ContactSettings, IpcContactTerm
// IpcContactTerm.contact_forces / contact_wrenches (bind_contact_forces.cpp)
pybind11::dict contact_forces_arrays(const IpcContactTerm& term, const VecX& q);
contact::WrenchMatrix contact_wrenches_array(const IpcContactTerm& term, const VecX& q,
                                             const MatX3& centers);
}  // namespace abd::bindings
