// IPC's edge–edge mollifier. Near-parallel edges switch between distance pieces without C¹
// continuity of the barrier; IPC multiplies the edge–edge barrier by
//     m(c) = (2 − c/ε_x) c/ε_x  for c < ε_x,  1 otherwise,   c = |ea × eb|²,
// with ε_x = 1e-3 |ēa|² |ēb|² from the rest edges (so it is scale free and constant in time).
// m is C¹ at c = ε_x and vanishes (with the barrier contribution) for exactly parallel edges;
// point–triangle pairs still hold those contacts.
#pragma once
#include "contact/stencil_types.h"

namespace abd::contact {

constexpr double kMollifierThresholdScale = 1e-3;

double edge_edge_mollifier_threshold(const Vec3& ea0_rest, const Vec3& ea1_rest,
                                     const Vec3& eb0_rest, const Vec3& eb1_rest);

// c = |(ea1 − ea0) × (eb1 − eb0)|² and its derivatives w.r.t. [ea0; ea1; eb0; eb1].
double edge_edge_cross_squarednorm(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                   const Vec3& eb1);
Vec12 edge_edge_cross_squarednorm_gradient(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                           const Vec3& eb1);
Mat12 edge_edge_cross_squarednorm_hessian(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                          const Vec3& eb1);

// m(c) and its first and second derivatives w.r.t. c.
double edge_edge_mollifier(double c, double eps_x);
double edge_edge_mollifier_derivative(double c, double eps_x);
double edge_edge_mollifier_second_derivative(double c, double eps_x);

// m(c(x)) with gradient and Hessian w.r.t. the 12 edge coordinates (order as affine_distance).
struct Mollifier {
  double value = 1.0;
  Vec12 grad = Vec12::Zero();
  Mat12 hess = Mat12::Zero();
  bool active = false;  // c < ε_x: derivatives are non-zero
};
Mollifier edge_edge_mollifier_derivatives(const Vec3& ea0, const Vec3& ea1, const Vec3& eb0,
                                          const Vec3& eb1, double eps_x, int order);

}  // namespace abd::contact
