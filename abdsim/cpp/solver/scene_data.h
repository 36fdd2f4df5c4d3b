// Plain data the Python Scene hands to the C++ solver: rest geometries (shared by
// instances) and bodies (one per instance). Everything the solver and the contact code
// need about the scene lives here; nothing in it refers back to Python.
#pragma once
#include <vector>

#include "common/types.h"

namespace abd {

struct GeometryData {
  MatX3 rest_vertices;  // x̄, (nv, 3)
  MatX3i triangles;     // surface triangles used for contact (may be empty for rods)
  MatX2i edges;         // surface edges used for contact (unique, derived from triangles or rod)
  VecX thickness;       // per vertex contact thickness radius r (0 for solids)
  int self_collision = 0;
  int dim = 3;          // 3 solid, 2 shell, 1 rod
};

struct BodyData {
  int geometry = 0;     // index into SceneData::geometries
  Vec12 q;              // initial state [p; a1; a2; a3]
  Vec12 q_dot;          // initial velocity
  double mass = 0.0;    // dyadic mass m
  Vec3 mass_x_bar = Vec3::Zero();
  Mat3 mass_x_bar_x_bar = Mat3::Zero();
  double kappa = 1e8;
  double volume = 0.0;
  int constitution_uid = 1;  // 1 OrthoPotential, 2 ARAP
  bool is_fixed = false;
  bool is_dynamic = true;
  bool external_kinetic = false;
};

struct SceneData {
  std::vector<GeometryData> geometries;
  std::vector<BodyData> bodies;
  double dt = 0.01;
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);
};

}  // namespace abd
