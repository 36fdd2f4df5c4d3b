// Small helpers shared by the World's translation units (world*.cpp).
#pragma once
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/types.h"

namespace abd::world_detail {

inline void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

// Newton outcome of one body (fast path) or of the whole system.
enum Status : int { kRunning = 0, kConverged, kMaxIterations, kLineSearch, kSingular, kNonFinite };

// Largest |Δp_k| / h and |ΔA_kl| / h of a 12-dof step.
inline void step_sizes(const Vec12& dq, double h, double& translation, double& affine) {
  translation = dq.head<3>().cwiseAbs().maxCoeff() / h;
  affine = dq.tail<9>().cwiseAbs().maxCoeff() / h;
}

// Roundoff allowance in the sufficient-decrease test: Π is a sum of terms of its own size,
// so a change below ~1e-12 |Π| is noise, not an increase.
inline double roundoff(double energy) { return 1e-12 * std::abs(energy); }

// A Newton direction this far below its tolerance (as a fraction of it) converges whatever
// the line search did with it: at that size step bounds and Armijo tests are noise. Above
// it, only a step taken whole converges (a shortened step says the model is off).
constexpr double kRoundoffStep = 1e-2;

// Per-body loops whose bodies cost well under a microsecond each are not worth handing to the
// worker pool below this many bodies.
constexpr int kLightLoop = 1024;

}  // namespace abd::world_detail
