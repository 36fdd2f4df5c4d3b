// A contact stencil: the vertices of one primitive pair (point–triangle, edge–edge, or a
// vertex against the ground), with what the pair needs besides positions: its thickness
// offset ξ, its edge–edge mollifier threshold and its friction coefficient. Stencils are built
// from broad-phase candidates and evaluated on world positions of all vertices.
#pragma once
#include <array>
#include <vector>

#include "contact/contact_mesh.h"
#include "contact/stencil_types.h"

namespace abd::contact {

enum class StencilKind : int { PointTriangle = 0, EdgeEdge = 1, PointGround = 2 };

struct ContactStencil {
  StencilKind kind = StencilKind::PointTriangle;
  int nv = 4;
  std::array<int, 4> vertices{};    // global ids: [p, t0, t1, t2] | [ea0, ea1, eb0, eb1] | [v]
  std::array<int, 2> primitives{};  // (vertex, face) | (edge, edge) | (vertex, -1)
  std::array<int, 2> bodies{};      // body of each side; -1 is the ground
  double xi = 0.0;                  // sum of both primitives' thickness radii
  double eps_x = 0.0;               // edge–edge mollifier threshold (0: not edge–edge)
  double mu = 0.0;                  // friction coefficient of the pair
  double damping = 0.0;             // damping ratio ζ of the pair (damping/normal_damping.h)
};

ContactStencil point_triangle_stencil(const ContactMesh& mesh, int vertex, int face, double mu);
ContactStencil edge_edge_stencil(const ContactMesh& mesh, int edge_a, int edge_b, double mu);
ContactStencil point_ground_stencil(const ContactMesh& mesh, int vertex, double mu);

// The squared distance of a stencil and what friction needs from its closest points.
struct StencilGeometry {
  double d2 = 0.0;
  bool infeasible = false;  // inside the thickness, or (ground) at or below the plane
  StencilVec grad;          // ∂d²/∂x over the stencil's 3·nv coordinates (order >= 1)
  StencilMat hess;          // ∂²d²/∂x² (order >= 2)
  // hess's factors (order >= 2, not the ground; affine_distance.h): hess = 2 (w wᵀ ⊗ I₃)
  // − 2 Cᵀ U⁻¹ C with row k of C = a_k ⊗ r + w ⊗ u_k, k < nb (the piece's parameters).
  Vec3 r;
  int nb = -1;  // -1: no factors (the ground, or order < 2)
  Eigen::Matrix<double, 4, 2> a;
  Eigen::Matrix<double, 3, 2> u;
  Eigen::Matrix2d U_inv;
  StencilWeights w;         // closest-point weights: r = Σ w_i x_i joins the closest points
  Mat3x2 basis;             // tangent basis of the contact (want_basis)
};

// What the barrier's value needs of a StencilGeometry (stencil_barrier_value).
struct StencilDistance {
  double d2 = 0.0;
  bool infeasible = false;
};

// dense_hessian = false (order 2): hess is left unset, only its factors are filled (a caller
// that projects in their structure, barrier_projection.h).
StencilGeometry stencil_geometry(const ContactStencil& s, const std::vector<Vec3>& x,
                                 double ground_height, int order, bool want_basis = false,
                                 bool dense_hessian = true);

// Stencil coordinates [x_{v0}; x_{v1}; ...] (3·nv values).
StencilVec gather_positions(const ContactStencil& s, const std::vector<Vec3>& x);

}  // namespace abd::contact
