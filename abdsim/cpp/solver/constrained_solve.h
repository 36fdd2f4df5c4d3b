// The Newton step under equality constraints (solver/constraint.h): the KKT system
//   [H Jᵀ; J 0] [x; λ] = [rhs; −c]
// solved as one sparse quasi-definite LDLᵀ (constrained_solve.cpp), H being SPD (the projected
// Newton matrix, or the mass matrix for a projection): a tree of joints costs about what its
// chain of 12x12 blocks costs. Exact (no stiffness), so a step from a point where linear
// constraints hold keeps them to round-off.
#pragma once
#include <vector>

#include "solver/block_system.h"
#include "solver/constraint.h"

namespace abd {

// x over every body (zero on the bodies fixed in `system`). Columns of fixed bodies are
// dropped from the rows (they are constants this solve); rows with no free column are
// ignored. Throws SolverError when H or the Schur complement cannot be factorised
// (redundant constraints, a loop).
void solve_constrained(const BlockSystem& system, const std::vector<ConstraintRow>& rows,
                       const VecX& rhs, VecX& x);

}  // namespace abd
