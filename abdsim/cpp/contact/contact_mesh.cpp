#include "contact/contact_mesh.h"

#include <algorithm>
#include <set>
#include <stdexcept>
#include <string>

#include "common/affine.h"

namespace abd::contact {
namespace {

std::vector<std::array<int, 2>> local_edges(const GeometryData& g) {
  std::vector<std::array<int, 2>> out;
  if (g.edges.rows() > 0 || g.triangles.rows() == 0) {
    for (Eigen::Index e = 0; e < g.edges.rows(); ++e) out.push_back({g.edges(e, 0), g.edges(e, 1)});
    return out;
  }
  std::set<std::array<int, 2>> unique;
  for (Eigen::Index f = 0; f < g.triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = g.triangles(f, k), b = g.triangles(f, (k + 1) % 3);
      unique.insert({std::min(a, b), std::max(a, b)});
    }
  return {unique.begin(), unique.end()};
}

void check_index(int i, int n, int body, const char* what) {
  if (i < 0 || i >= n)
    throw std::invalid_argument("body " + std::to_string(body) + ": " + what +
                                " refers to vertex " + std::to_string(i) + " of " +
                                std::to_string(n));
}

}  // namespace

ContactMesh ContactMesh::from_scene(const SceneData& scene) {
  ContactMesh m;
  const int n_geometries = int(scene.geometries.size());
  for (int b = 0; b < int(scene.bodies.size()); ++b) {
    const BodyData& body = scene.bodies[b];
    if (body.geometry < 0 || body.geometry >= n_geometries)
      throw std::invalid_argument("body " + std::to_string(b) + " refers to geometry " +
                                  std::to_string(body.geometry) + " of " +
                                  std::to_string(n_geometries));
    const GeometryData& g = scene.geometries[body.geometry];
    const int nv = int(g.rest_vertices.rows());
    if (g.thickness.size() != 0 && g.thickness.size() != nv)
      throw std::invalid_argument("body " + std::to_string(b) + ": thickness has " +
                                  std::to_string(g.thickness.size()) + " values for " +
                                  std::to_string(nv) + " vertices");
    const int v0 = m.vertex_offset.back();
    double r_max = 0.0;
    for (int i = 0; i < nv; ++i) {
      m.rest.push_back(g.rest_vertices.row(i).transpose());
      const double r = g.thickness.size() ? g.thickness[i] : 0.0;
      if (!(r >= 0.0)) throw std::invalid_argument("body " + std::to_string(b) + ": negative thickness");
      m.thickness.push_back(r);
      m.vertex_body.push_back(b);
      r_max = std::max(r_max, r);
    }
    for (Eigen::Index f = 0; f < g.triangles.rows(); ++f) {
      std::array<int, 3> t;
      for (int k = 0; k < 3; ++k) {
        check_index(g.triangles(f, k), nv, b, "a triangle");
        t[k] = v0 + g.triangles(f, k);
      }
      m.faces.push_back(t);
      m.face_body.push_back(b);
    }
    for (const auto& e : local_edges(g)) {
      check_index(e[0], nv, b, "an edge");
      check_index(e[1], nv, b, "an edge");
      m.edges.push_back({v0 + e[0], v0 + e[1]});
      m.edge_body.push_back(b);
    }
    m.vertex_offset.push_back(int(m.rest.size()));
    m.edge_offset.push_back(int(m.edges.size()));
    m.face_offset.push_back(int(m.faces.size()));
    m.body_thickness.push_back(r_max);
    m.self_collision.push_back(g.self_collision != 0);
    m.fixed.push_back(body.is_fixed);
    m.mass.push_back(body.mass);
  }
  return m;
}

std::vector<Vec3> ContactMesh::world_vertices(const VecX& q) const {
  std::vector<Vec3> x;
  world_vertices_into(q, x);
  return x;
}

void ContactMesh::world_vertices_into(const VecX& q, std::vector<Vec3>& x) const {
  if (q.size() != 12 * num_bodies())
    throw std::invalid_argument("q has " + std::to_string(q.size()) + " values, expected 12 x " +
                                std::to_string(num_bodies()) + " bodies");
  x.resize(rest.size());
  for (int b = 0; b < num_bodies(); ++b) {
    const Vec12 qb = q.segment<12>(12 * b);
    for (int i = vertex_offset[b]; i < vertex_offset[b + 1]; ++i) x[i] = affine_point(qb, rest[i]);
  }
}

double ContactMesh::edge_thickness(int e) const {
  return std::max(thickness[edges[e][0]], thickness[edges[e][1]]);
}

double ContactMesh::face_thickness(int f) const {
  const auto& t = faces[f];
  return std::max({thickness[t[0]], thickness[t[1]], thickness[t[2]]});
}

}  // namespace abd::contact
