// The Newton system's sparse direct solve on its own (BlockSystem::solve_direct), for tests
// against a dense reference: one object keeps its factorisation's analysis between solves,
// as the World does between Newton iterations.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include "bindings/bindings.h"
#include "solver/block_system.h"

namespace py = pybind11;

namespace abd::bindings {

void bind_block_system(py::module_& m) {
  using MatX12 = Eigen::Matrix<double, Eigen::Dynamic, 12, Eigen::RowMajor>;
  using Coupling = std::tuple<int, int, Mat12>;
  py::class_<BlockSystem>(m, "BlockDirectSolve",
                          "BlockSystem.solve_direct: solve(diagonal, couplings, fixed, rhs) -> "
                          "(x (n, 12), whether a new symbolic analysis ran)")
      .def(py::init<>())
      .def(
          "solve",
          [](BlockSystem& system, const std::vector<Mat12>& diagonal,
             const std::vector<Coupling>& couplings, const std::vector<int>& fixed,
             const MatX12& rhs) {
            const int n = static_cast<int>(diagonal.size());
            if (static_cast<int>(fixed.size()) != n || rhs.rows() != n)
              throw std::invalid_argument("solve: diagonal, fixed and rhs need one entry per body");
            system.reset(n, std::vector<std::uint8_t>(fixed.begin(), fixed.end()));
            for (int b = 0; b < n; ++b) system.diagonal(b) = fixed[b] ? Mat12::Zero() : diagonal[b];
            std::vector<BodyBlock> blocks;  // add_blocks checks the bodies (SolverError)
            for (const Coupling& c : couplings)
              blocks.push_back({std::get<0>(c), std::get<1>(c), std::get<2>(c)});
            system.add_blocks(blocks);
            system.finalize();
            VecX b(12 * n), x;
            Eigen::Map<MatX12>(b.data(), n, 12) = rhs;
            const bool analysed = system.solve_direct(b, x);
            return std::make_pair(MatX12(Eigen::Map<const MatX12>(x.data(), n, 12)), analysed);
          },
          py::arg("diagonal"), py::arg("couplings"), py::arg("fixed"), py::arg("rhs"));
}

}  // namespace abd::bindings
