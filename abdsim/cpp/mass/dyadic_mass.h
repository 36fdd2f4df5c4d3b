// Dyadic mass of an affine body (ABD_NOTES §2-4): m = ∫ρ, m x̄ = ∫ρ x̄, S = ∫ρ x̄ x̄ᵀ,
// with exact closed forms per simplex, and the rigid-body view of it.
#pragma once
#include "common/types.h"

namespace abd {

struct DyadicMass {
  double m = 0.0;
  Vec3 m_x_bar = Vec3::Zero();
  Mat3 S = Mat3::Zero();

  DyadicMass& operator+=(const DyadicMass& o) {
    m += o.m;
    m_x_bar += o.m_x_bar;
    S += o.S;
    return *this;
  }
  // The same mass distribution expressed about origin - o (integrals were taken relative to
  // a reference point o to avoid cancellation far from the origin).
  DyadicMass shifted_by(const Vec3& o) const;
  // The 12x12 ABD mass matrix (ABD_NOTES §3).
  Mat12 matrix() const;
};

struct RigidBodyProperties {
  double mass;
  Vec3 center;
  Mat3 inertia;  // about the centre of mass, ∫ρ(|x|²I - xxᵀ)
};

// Solid tetrahedral mesh; signed volumes are summed, so tets must be positively oriented
// (the Python layer checks this).
DyadicMass tet_mesh_mass(const MatX3& V, const MatX4i& T, double rho);
// Closed, outward-oriented triangle surface treated as a solid (divergence theorem).
DyadicMass closed_surface_mass(const MatX3& V, const MatX3i& F, double rho);
// Shell: slab of full thickness 2r around each triangle (r per vertex, averaged per face).
DyadicMass shell_mass(const MatX3& V, const MatX3i& F, const VecX& r, double rho);
// Rod: cylinder of radius r around each segment (r per vertex, averaged per edge).
DyadicMass rod_mass(const MatX3& V, const MatX2i& E, const VecX& r, double rho);

RigidBodyProperties to_rigid_body(const DyadicMass& dm);
DyadicMass from_rigid_body(double mass, const Vec3& center, const Mat3& inertia);

}  // namespace abd
