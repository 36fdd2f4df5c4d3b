// The interface every potential in the incremental potential implements (shape energy,
// joints, IPC barrier, friction, ...). The Newton solver owns q and knows nothing about what
// a term computes; a term only sees the stacked body state q (12 * n_bodies) and
// returns values, gradients and PSD Hessian blocks in 12x12 body-block form.
//
// Conventions:
//  * value/gradient/hessian are the *potential* (not multiplied by h^2): the solver scales.
//  * add_gradient / add_hessian ADD `scale *` their contribution.
//  * Hessian blocks must be PSD as a whole (project per element before mapping J^T H J).
//  * Results must be deterministic: no accumulation order that depends on thread timing.
#pragma once
#include <string>
#include <vector>

#include "common/types.h"

namespace abd {

// One 12x12 block of the global Hessian, for body rows `row` and body columns `col`.
struct BodyBlock {
  int row;
  int col;
  Mat12 H;
};

struct StepContext {
  double dt;
  const VecX& q_t;      // state at the start of the step
  const VecX& q_dot_t;  // velocity at the start of the step
};

class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;
  virtual std::string name() const = 0;

  // Once per time step, before Newton starts (lagged quantities, e.g. friction bases).
  virtual void begin_step(const StepContext& /*ctx*/) {}
  // Whenever Newton accepts a new iterate (e.g. rebuild the active contact set).
  virtual void update(const VecX& /*q*/) {}

  virtual double value(const VecX& q) const = 0;
  virtual void add_gradient(const VecX& q, double scale, VecX& gradient) const = 0;
  virtual void add_hessian(const VecX& q, double scale, std::vector<BodyBlock>& blocks) const = 0;

  // Largest alpha in (0, 1] such that the straight path q + t*dq, t in [0, alpha], stays
  // feasible (continuous collision detection). Terms without feasibility constraints
  // return 1.
  virtual double max_step(const VecX& /*q*/, const VecX& /*dq*/) const { return 1.0; }
};

}  // namespace abd
