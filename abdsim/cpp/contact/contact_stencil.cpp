#include "contact/contact_stencil.h"

#include <algorithm>

#include "contact/distance/distance.h"
#include "contact/distance/edge_edge_mollifier.h"
#include "contact/friction/tangent_basis.h"
#include "contact/ground/ground_plane.h"

namespace abd::contact {
namespace {

// The tangent plane of a smooth piece, from the vertices the piece uses.
Mat3x2 piece_basis(const stencil::Piece& piece, const std::array<Vec3, 4>& y) {
  const auto& i = piece.idx;
  switch (piece.kind) {
    case stencil::PieceKind::PointPoint: return point_point_tangent_basis(y[i[0]], y[i[1]]);
    case stencil::PieceKind::PointLine: return point_edge_tangent_basis(y[i[0]], y[i[1]], y[i[2]]);
    case stencil::PieceKind::PointPlane:
      return point_triangle_tangent_basis(y[i[0]], y[i[1]], y[i[2]], y[i[3]]);
    default: return edge_edge_tangent_basis(y[i[0]], y[i[1]], y[i[2]], y[i[3]]);
  }
}

template <class Distance>
void fill_from(const Distance& d, const stencil::Piece& piece, const std::array<Vec3, 4>& y,
               int order, bool want_basis, bool dense_hessian, StencilGeometry& g) {
  g.d2 = d.d2;
  g.w = d.w;
  if (order >= 1) g.grad = d.grad;
  if (order >= 2) {
    if (dense_hessian) g.hess = d.hess;
    g.r = d.r;
    g.nb = d.nb;
    g.a = d.a;
    g.u = d.u;
    g.U_inv = d.U_inv;
  }
  if (want_basis) g.basis = piece_basis(piece, y);
}

}  // namespace

ContactStencil point_triangle_stencil(const ContactMesh& mesh, int vertex, int face, double mu) {
  ContactStencil s;
  s.kind = StencilKind::PointTriangle;
  s.nv = 4;
  const auto& f = mesh.faces[face];
  s.vertices = {vertex, f[0], f[1], f[2]};
  s.primitives = {vertex, face};
  s.bodies = {mesh.vertex_body[vertex], mesh.face_body[face]};
  s.xi = mesh.thickness[vertex] + mesh.face_thickness(face);
  s.mu = mu;
  return s;
}

ContactStencil edge_edge_stencil(const ContactMesh& mesh, int edge_a, int edge_b, double mu) {
  ContactStencil s;
  s.kind = StencilKind::EdgeEdge;
  s.nv = 4;
  const auto& a = mesh.edges[edge_a];
  const auto& b = mesh.edges[edge_b];
  s.vertices = {a[0], a[1], b[0], b[1]};
  s.primitives = {edge_a, edge_b};
  s.bodies = {mesh.edge_body[edge_a], mesh.edge_body[edge_b]};
  s.xi = mesh.edge_thickness(edge_a) + mesh.edge_thickness(edge_b);
  // Rest lengths are frame independent, so each edge's own body frame serves.
  s.eps_x = edge_edge_mollifier_threshold(mesh.rest[a[0]], mesh.rest[a[1]], mesh.rest[b[0]],
                                          mesh.rest[b[1]]);
  s.mu = mu;
  return s;
}

ContactStencil point_ground_stencil(const ContactMesh& mesh, int vertex, double mu) {
  ContactStencil s;
  s.kind = StencilKind::PointGround;
  s.nv = 1;
  s.vertices = {vertex, -1, -1, -1};
  s.primitives = {vertex, -1};
  s.bodies = {mesh.vertex_body[vertex], -1};
  s.xi = mesh.thickness[vertex];
  s.mu = mu;
  return s;
}

StencilVec gather_positions(const ContactStencil& s, const std::vector<Vec3>& x) {
  StencilVec out(3 * s.nv);
  for (int i = 0; i < s.nv; ++i) out.segment<3>(3 * i) = x[s.vertices[i]];
  return out;
}

StencilGeometry stencil_geometry(const ContactStencil& s, const std::vector<Vec3>& x,
                                 double ground_height, int order, bool want_basis,
                                 bool dense_hessian) {
  StencilGeometry g;
  if (s.kind == StencilKind::PointGround) {
    const Vec3& p = x[s.vertices[0]];
    g.d2 = point_ground_distance(p, ground_height);
    g.infeasible = point_ground_signed_distance(p, ground_height) <= s.xi;
    g.w = StencilWeights::Ones(1);
    if (order >= 1) g.grad = point_ground_distance_gradient(p, ground_height);
    if (order >= 2) g.hess = point_ground_distance_hessian();
    if (want_basis) g.basis = ground_tangent_basis();
    return g;
  }
  std::array<Vec3, 4> y;
  for (int i = 0; i < 4; ++i) y[i] = x[s.vertices[i]];
  if (s.kind == StencilKind::PointTriangle) {
    const auto type = point_triangle_distance_type(y[0], y[1], y[2], y[3]);
    const stencil::Piece& piece = point_triangle_piece(type);
    fill_from(stencil::evaluate_piece<4>(y, piece, order, dense_hessian), piece, y, order, want_basis,
              dense_hessian, g);
  } else {
    const auto type = edge_edge_distance_type(y[0], y[1], y[2], y[3]);
    const stencil::Piece& piece = edge_edge_piece(type);
    fill_from(stencil::evaluate_piece<4>(y, piece, order, dense_hessian), piece, y, order, want_basis,
              dense_hessian, g);
  }
  g.infeasible = g.d2 <= s.xi * s.xi;
  return g;
}

}  // namespace abd::contact
