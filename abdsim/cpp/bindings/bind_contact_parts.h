// The contact submodule is bound in parts, one translation unit each (bind_contact.cpp
// creates `abdsim._core.contact` and calls them).
#pragma once
#include <pybind11/pybind11.h>

namespace abd::bindings {
void bind_contact_primitives(pybind11::module_& m);  // distances, barrier, CCD, friction
void bind_contact_term(pybind11::module_& m);        // ContactSettings, IpcContactTerm
}  // namespace abd::bindings
