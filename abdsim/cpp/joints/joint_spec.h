// A joint between two affine bodies (or a body and the world) as the user gives it, and the
// rest-space data the constraints use, fixed once at load (ABD_NOTES §8).
#pragma once
#include <string>

#include "common/types.h"

namespace abd {

enum class JointKind : int { kFree = 0, kBall = 1, kRevolute = 2, kPrismatic = 3, kFixed = 4 };

// Joint coordinates per kind (MuJoCo's conventions): qpos and qvel sizes.
inline int joint_nq(JointKind k) {
  return k == JointKind::kFree ? 7 : k == JointKind::kBall ? 4 : k == JointKind::kFixed ? 0 : 1;
}
inline int joint_nv(JointKind k) {
  return k == JointKind::kFree ? 6 : k == JointKind::kBall ? 3 : k == JointKind::kFixed ? 0 : 1;
}

struct JointSpec {
  JointKind kind = JointKind::kRevolute;
  int parent = -1;  // body index, −1 for the world
  int child = -1;
  Vec3 anchor = Vec3::Zero();  // world position at load
  Vec3 axis = Vec3::UnitZ();   // world direction at load (revolute, prismatic)
  std::string name;
};

// Rest-space (x̄) images of the joint's world data at load, in the parent (world coordinates
// when the parent is the world) and in the child. Points map by x̄ = A₀⁻¹(x − p₀),
// directions by ē = A₀⁻¹ e, so A ē reproduces the world direction at load exactly.
struct JointFrame {
  JointSpec spec;
  Vec3 anchor_p, anchor_c;  // the anchor
  Vec3 tip_p, tip_c;        // the point anchor + lever · axis (revolute's second point)
  double lever = 1.0;       // m
  Vec3 axis_p;              // the axis, in the parent
  Mat3 basis_p, basis_c;    // columns: the world unit directions e1, e2, e3
  Vec3 normal_p, normal_c;  // a unit direction ⊥ axis at load (hinge angle reference)
  Vec3 normal2_p;           // axis × normal, in the parent (prismatic offset rows)
  Mat3 rel0;                // R_p₀ᵀ R_c₀ (ball reference)
};

}  // namespace abd
