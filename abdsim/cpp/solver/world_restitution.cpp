// The restitution law after a committed step (contact/damping/restitution.h,
// docs/restitution.md): it changes velocities only, so it runs on the committed state.
#include "common/affine.h"
#include "contact/ipc_contact_term.h"
#include "solver/world.h"

namespace abd {

void World::apply_restitution(StepDiagnostics& d) {
  if (!contact_ || !contact_->has_restitution()) return;
  const auto e_of = [&](int a, int b) { return contact_->restitution(a, b); };
  const auto inertia = [&](int b, const VecX& q) {
    contact::RestitutionLaw::Inertia in;
    if (fixed_[b] || kinematic_[b] || !dynamic_[b] || external_kinetic_[b]) return in;
    const DyadicMass& dm = dyadic_[b];
    in.mass = dm.m;
    in.center = dm.m_x_bar / dm.m;
    in.second_moment = dm.S - dm.m_x_bar * dm.m_x_bar.transpose() / dm.m;
    in.mass_matrix = dm.matrix();
    const Vec12 qb = q.segment<12>(12 * b);
    // −m g · (centre of mass) + Ψ
    in.potential = -dm.m * scene_.gravity.dot(affine_point(qb, in.center)) + shape_.body_value(b, qb);
    return in;
  };
  d.restitution_impulses = restitution_.after_step(
      contact_->contact_forces(q_), step_q_t_, step_q_dot_t_, q_, q_dot_, scene_.gravity,
      contact_->settings().restitution_threshold, e_of, inertia);
  // A velocity jump: BDF2 restarts (its extrapolation would cross it).
  if (d.restitution_impulses > 0) has_history_ = false;
}

}  // namespace abd
