// A BDF2 history for a body whose real one is unusable: after a velocity jump (a restitution
// impulse) or after a step done in pieces (the previous state is a piece ago, not a step).
//
// BDF2 extrapolates from two states one step h apart: q̂ = (4 q − q_prev) / 3 and
// v̂ = (4 q̇ − q̇_prev) / 3. Without a valid previous state it used to restart with one BDF1
// step, whose free flight is low by ½ a h² (a 5 cm rebound at h = 1e-2 lost 4 % of its
// height). Instead, the previous state is put where the body would have been had it moved
// with a constant acceleration a up to the current state:
//   q_prev = q − h q̇ + ½ h² a,   q̇_prev = q̇ − h a.
// BDF2 integrates a constant acceleration exactly (its error term is h³ q⃛), so with a = g a
// ballistic body then follows its parabola to round-off from the very next step.
#pragma once
#include "common/types.h"

namespace abd::bdf_history {

struct State {
  Vec12 q, q_dot;
};

// The state one step h before (q, q_dot) along a path of constant acceleration `a` (all
// 12 dofs).
inline State constant_acceleration(const Vec12& q, const Vec12& q_dot, const Vec12& a,
                                   double h) {
  return {q - h * q_dot + 0.5 * h * h * a, q_dot - h * a};
}

// Gravity's acceleration on the 12 dofs (translation only: A has no gravity).
inline Vec12 gravity_acceleration(const Vec3& gravity) {
  Vec12 a = Vec12::Zero();
  a.head<3>() = gravity;
  return a;
}

}  // namespace abd::bdf_history
