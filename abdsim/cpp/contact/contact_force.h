// What the contact term reports about the forces it applies: one record per contact pair
// (a primitive pair, or a vertex and the ground). The forces are those of the potentials at
// the state asked about, −∇_x (B + D) in vertex space; the solver's converged step satisfies
// M (q − q̃)/c² + ∇Ψ + ∇B + ∇D = 0 with B and D unscaled (the solver applies c²), so these are
// the forces (N) the step applied to each body.
#pragma once
#include <array>

#include "common/types.h"

namespace abd::contact {

struct ContactForce {
  // First side, second side; -1 is the ground. The first side is the point of a
  // point–triangle or point–ground pair, the first edge of an edge–edge pair.
  std::array<int, 2> bodies{{-1, -1}};
  Vec3 point = Vec3::Zero();     // midpoint of the two closest points (world, m)
  Vec3 normal = Vec3::Zero();    // unit, from the second side towards the first
  double normal_force = 0.0;     // barrier (+ damping) force on the first side along `normal` (N)
  Vec3 friction = Vec3::Zero();  // friction force on the first side (N); the second gets −it
  double energy = 0.0;           // the pair's barrier energy (J) (damping/restitution.h)
};

// Per-body wrenches, one row [f, τ] per body.
using WrenchMatrix = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>;

}  // namespace abd::contact
