// Π and its parts as the coupled solve evaluates them: per body (kinetic or drive, shape),
// per island (terms that split by body), in total (diagnostics), and the terms' step bounds.
#include <algorithm>
#include <array>
#include <numeric>
#include <vector>

#include "common/affine.h"
#include "solver/body_math.h"
#include "solver/parallel.h"
#include "solver/world.h"
#include "solver/world_detail.h"

namespace abd {
using namespace world_detail;

// A driven body is the same body s times heavier *and* s times stiffer heading for its
// target: s (½|x − target|²_M + c² Ψ). Scaling the shape energy with the drive keeps the
// balance of a normal body (it does not get squashed against what stops it).
double World::body_energy(int b, const Vec12& x, double c2, Vec12* g, Mat12* H) const {
  const DyadicMass& dm = dyadic_[b];
  const Vec12 r = x - q_tilde_.segment<12>(12 * b);
  const bool kinetic = driven_[b] || !external_kinetic_[b];
  double e = 0.0;
  if (!g && !H) {
    if (kinetic) e = mass_quadratic(dm, r);
    e += c2 * shape_.body_value(b, x);
    return driven_[b] ? settings_.kinematic_drive_stiffness * e : e;
  }
  // Built in the caller's g and H (the shape energy adds to them).
  Vec12 g_scratch;
  Mat12 H_scratch;
  Vec12& gb = g ? *g : g_scratch;
  Mat12& Hb = H ? *H : H_scratch;
  if (kinetic) {
    gb = mass_times(dm, r);
    e = 0.5 * r.dot(gb);
    Hb = mass_matrix_[b];
  } else {
    gb.setZero();
    Hb.setZero();
  }
  // The kinetic term's curvature absorbs a little negative curvature of the shape energy's:
  // the block stays positive definite without the shape Hessian's projection there.
  e += c2 * shape_.add_body_derivatives(b, x, c2, gb, Hb, kinetic ? mass_floor_[b] : 0.0);
  if (driven_[b]) {
    const double s = settings_.kinematic_drive_stiffness;
    e *= s;
    gb *= s;
    Hb *= s;
  }
  return e;
}

double World::body_energies(const VecX& x, double c2, VecX& E,
                            std::vector<BodyLink>& links) const {
  E.resize(n_);
  parallel_for(
      n_, threads_,
      [&](int b) {
        E[b] = movable_[b] ? body_energy(b, x.segment<12>(12 * b), c2, nullptr, nullptr) : 0.0;
      },
      kLightLoop);
  double rest = 0.0;
  for (const auto& t : terms_) {
    if (t->splits_by_body()) {
      VecX per_body = VecX::Zero(n_);
      t->add_body_values(x, movable_, per_body, links);
      E += c2 * per_body;
    } else {
      rest += c2 * t->value(x);
    }
  }
  return rest;
}

// Π at x for the diagnostics; `parts`: kinetic, shape, drive (the driven bodies' whole
// share of Π, in Π's units), then each term's value.
double World::total_energy(const VecX& x, double c2, std::vector<double>* parts) const {
  // Kinetic, drive and shape in one pass over the bodies (deterministic_sums: each summed in
  // body order within fixed chunks, whatever the thread count).
  const auto [kinetic, drive, shape] =
      deterministic_sums<3>(n_, threads_, [&](int b) -> std::array<double, 3> {
        const auto xb = x.segment<12>(12 * b);
        if (driven_[b]) return {0.0, body_energy(b, xb, c2, nullptr, nullptr), 0.0};
        const double ek = constrained_[b] || external_kinetic_[b]
                              ? 0.0
                              : mass_quadratic(dyadic_[b], xb - q_tilde_.segment<12>(12 * b));
        return {ek, 0.0, shape_.body_value(b, xb)};
      });
  double potential = shape;
  if (parts) parts->assign({kinetic, shape, drive});
  for (const auto& t : terms_) {
    const double v = t->value(x);
    potential += v;
    if (parts) parts->push_back(v);
  }
  return kinetic + drive + c2 * potential;
}

// Step bounds of the move x → x + dq: per body (bound_, from terms that split by body, for
// the bodies in `mask`) and the bound of the terms that do not split (returned); `near` and
// `links` as in EnergyTerm::body_max_steps.
double World::step_bounds(const VecX& x, const VecX& dq, const std::vector<unsigned char>& mask,
                          std::vector<unsigned char>& near, std::vector<BodyLink>& links) {
  bound_.setOnes(n_);
  near.assign(n_, 0);
  double global = 1.0;
  for (const auto& t : terms_) {
    if (t->splits_by_body())
      t->body_max_steps(x, dq, mask, bound_, near, links);
    else
      global = std::min(global, t->max_step(x, dq));
  }
  return global;
}

}  // namespace abd
