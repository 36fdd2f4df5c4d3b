// The contact surface of the whole scene, flattened into global primitive tables: every body
// instance gets its own block of vertex, edge and face ids (body b owns vertices
// [vertex_offset[b], vertex_offset[b + 1]), and likewise for edges and faces). Global ids are
// what candidate pairs, stencils and diagnostics speak; a vertex moves with its body as
// x = A x̄ + p (common/affine.h).
#pragma once
#include <array>
#include <vector>

#include "common/types.h"
#include "solver/scene_data.h"

namespace abd::contact {

struct ContactMesh {
  std::vector<int> vertex_offset{0}, edge_offset{0}, face_offset{0};  // n_bodies + 1 each
  std::vector<Vec3> rest;             // x̄ of each global vertex (in its body's frame)
  std::vector<double> thickness;      // contact thickness radius r of each vertex (0: solid)
  std::vector<int> vertex_body;
  std::vector<std::array<int, 2>> edges;  // global vertex ids
  std::vector<std::array<int, 3>> faces;  // global vertex ids
  std::vector<int> edge_body, face_body;
  std::vector<double> body_thickness;     // largest r on each body
  std::vector<char> self_collision, fixed;
  std::vector<double> mass;

  // Throws std::invalid_argument on inconsistent input (bad geometry index, out-of-range
  // vertex ids, thickness of the wrong size). A geometry with triangles but no edges gets its
  // unique triangle edges.
  static ContactMesh from_scene(const SceneData& scene);

  int num_bodies() const { return int(vertex_offset.size()) - 1; }
  int num_vertices() const { return int(rest.size()); }

  // World positions of every vertex for the stacked body state q (12 per body).
  std::vector<Vec3> world_vertices(const VecX& q) const;
  // The same into `x` (resized; its storage is reused from call to call).
  void world_vertices_into(const VecX& q, std::vector<Vec3>& x) const;

  // Largest r among a primitive's vertices: a primitive's thickness.
  double edge_thickness(int e) const;
  double face_thickness(int f) const;
};

}  // namespace abd::contact
