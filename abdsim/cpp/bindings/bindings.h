// Each concept binds itself in its own translation unit; module.cpp only calls them.
#pragma once
#include <pybind11/pybind11.h>

namespace abd::bindings {
void bind_mass(pybind11::module_& m);
void bind_energy(pybind11::module_& m);
void bind_solver(pybind11::module_& m);
void bind_contact(pybind11::module_& m);
void bind_joints(pybind11::module_& m);
void bind_block_system(pybind11::module_& m);
}  // namespace abd::bindings
