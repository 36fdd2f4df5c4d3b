#include "bindings/bindings.h"

#include <Eigen/Core>
#include <coal/config.hh>
#include <string>

PYBIND11_MODULE(_core, m) {
  m.doc() = "abdsim C++ core: dyadic mass, shape energies, implicit solver, IPC contact, joints";
  m.attr("coal_version") = COAL_VERSION;
  m.def(
      "simd_instruction_sets", [] { return std::string(Eigen::SimdInstructionSetsInUse()); },
      "The SIMD instruction sets the core's Eigen kernels were compiled for (Eigen's "
      "SimdInstructionSetsInUse: 'AVX SSE, SSE2, SSE3, SSSE3, SSE4.1, SSE4.2' for a native "
      "build on an AVX2 machine; AVX-512 is left off, cmake/core/CMakeLists.txt says why).");
  abd::bindings::bind_mass(m);
  abd::bindings::bind_energy(m);
  abd::bindings::bind_solver(m);
  abd::bindings::bind_contact(m);
  abd::bindings::bind_joints(m);
  abd::bindings::bind_block_system(m);
}
