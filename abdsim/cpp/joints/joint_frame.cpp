#include "joints/joint_frame.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "joints/joint_state.h"

namespace abd {
namespace {

std::string label(const JointSpec& s) {
  return "joint '" + (s.name.empty() ? std::string("?") : s.name) + "'";
}

// Centre of mass (world, at load) and the largest distance of a vertex from it.
void body_extent(const SceneData& scene, const VecX& q0, int b, Vec3& center, double& radius) {
  const BodyData& body = scene.bodies[b];
  const Vec12 q = q0.segment<12>(12 * b);
  center = affine_point(q, body.mass_x_bar / body.mass);
  radius = 0.0;
  if (scene.geometries.empty()) return;
  const MatX3& rest = scene.geometries[body.geometry].rest_vertices;
  for (Eigen::Index v = 0; v < rest.rows(); ++v)
    radius = std::max(radius, (affine_point(q, rest.row(v).transpose()) - center).norm());
}

}  // namespace

JointFrame make_joint_frame(const JointSpec& spec, const SceneData& scene, const VecX& q0) {
  const int n = static_cast<int>(scene.bodies.size());
  auto fail = [&](const std::string& what) {
    throw std::invalid_argument(label(spec) + ": " + what);
  };
  if (spec.child < 0 || spec.child >= n)
    fail("child body " + std::to_string(spec.child) + " out of range");
  if (spec.parent < -1 || spec.parent >= n)
    fail("parent body " + std::to_string(spec.parent) + " out of range");
  if (spec.parent == spec.child) fail("parent and child are the same body");
  if (!spec.anchor.allFinite()) fail("anchor is not finite");
  const bool axial = spec.kind == JointKind::kRevolute || spec.kind == JointKind::kPrismatic;
  if (axial && !(spec.axis.allFinite() && spec.axis.norm() > 1e-12))
    fail("axis is zero or not finite");
  if (spec.kind == JointKind::kFree && spec.parent >= 0)
    fail("a free joint must have the world as parent");

  // The anchor must lie near one of the two bodies (within twice its size of its centre).
  if (spec.kind != JointKind::kFree) {
    double nearest = 1e300, size = 0.0;
    for (int b : {spec.parent, spec.child}) {
      if (b < 0) continue;
      Vec3 c;
      double r;
      body_extent(scene, q0, b, c, r);
      const double gap = (spec.anchor - c).norm() - 2.0 * r;
      if (gap < nearest) {
        nearest = gap;
        size = r;
      }
    }
    if (nearest > 1e-9 && size >= 0.0)
      fail("anchor (" + std::to_string(spec.anchor.x()) + ", " + std::to_string(spec.anchor.y()) +
           ", " + std::to_string(spec.anchor.z()) + ") is far from both bodies");
  }

  JointFrame f;
  f.spec = spec;
  const Vec3 t = axial ? Vec3(spec.axis.normalized()) : Vec3::UnitZ();
  f.spec.axis = t;
  Vec3 c_child;
  double r_child;
  body_extent(scene, q0, spec.child, c_child, r_child);
  f.lever = r_child > 1e-3 ? r_child : 1.0;

  const Vec12 qp = body_q(q0, spec.parent), qc = body_q(q0, spec.child);
  Mat3 Ap_inv, Ac_inv;
  bool ok_p = false, ok_c = false;
  double det = 0.0;
  affine_A(qp).computeInverseAndDetWithCheck(Ap_inv, det, ok_p, 1e-12);
  affine_A(qc).computeInverseAndDetWithCheck(Ac_inv, det, ok_c, 1e-12);
  if (!ok_p || !ok_c) fail("a body's transform is singular at load");
  auto rest_p = [&](const Vec3& x) -> Vec3 { return Ap_inv * (x - affine_p(qp)); };
  auto rest_c = [&](const Vec3& x) -> Vec3 { return Ac_inv * (x - affine_p(qc)); };
  f.anchor_p = rest_p(spec.anchor);
  f.anchor_c = rest_c(spec.anchor);
  f.tip_p = rest_p(spec.anchor + f.lever * t);
  f.tip_c = rest_c(spec.anchor + f.lever * t);
  f.axis_p = Ap_inv * t;
  f.basis_p = Ap_inv;  // columns A₀⁻¹ e_j
  f.basis_c = Ac_inv;
  // A unit normal to t: the world axis least aligned with it, made orthogonal.
  Eigen::Index least = 0;
  t.cwiseAbs().minCoeff(&least);
  const Vec3 normal = (Vec3::Unit(least) - t[least] * t).normalized();
  f.normal_p = Ap_inv * normal;
  f.normal_c = Ac_inv * normal;
  f.normal2_p = Ap_inv * t.cross(normal);
  f.rel0 = nearest_rotation(affine_A(qp)).transpose() * nearest_rotation(affine_A(qc));
  return f;
}

}  // namespace abd
