// The restitution law after a committed step (contact/damping/restitution.h,
// docs/restitution.md): it changes velocities only, so it runs on the committed state.
#include <vector>

#include "common/affine.h"
#include "contact/ipc_contact_term.h"
#include "solver/bdf_history.h"
#include "solver/world.h"

namespace abd {
namespace {

// Marks the bodies of every contact record (the ground, −1, has no flag).
void mark_in_contact(const std::vector<contact::ContactForce>& forces,
                     std::vector<unsigned char>& flags) {
  for (const contact::ContactForce& f : forces)
    for (int b : f.bodies)
      if (b >= 0) flags[b] = 1;
}

}  // namespace

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
  const std::vector<contact::ContactForce> forces = contact_->contact_forces(q_);
  const VecX q_dot_before = q_dot_;
  d.restitution_impulses = restitution_.after_step(
      forces, step_q_t_, step_q_dot_t_, q_, q_dot_, scene_.gravity,
      contact_->settings().restitution_threshold, e_of, inertia);
  if (d.restitution_impulses == 0) return;

  // A velocity jump: BDF2's history (the state a step ago) would extrapolate across it. The
  // bodies it changed get the ballistic history of their new velocity instead
  // (bdf_history.h): the impulses leave them separating, into free flight, which BDF2 then
  // follows exactly (a BDF1 restart step lost ½ g h² of the rebound).
  const double h = scene_.dt;
  const Vec12 g = bdf_history::gravity_acceleration(scene_.gravity);
  std::vector<unsigned char> restarted(n_, 0);
  for (int b = 0; b < n_; ++b) {
    if (q_dot_.segment<12>(12 * b) == q_dot_before.segment<12>(12 * b)) continue;
    const Vec12 q = q_.segment<12>(12 * b), v = q_dot_.segment<12>(12 * b);
    const bdf_history::State s = bdf_history::constant_acceleration(q, v, g, h);
    q_prev_.segment<12>(12 * b) = s.q;
    q_dot_prev_.segment<12>(12 * b) = s.q_dot;
    restarted[b] = 1;
  }
  if (has_history_ || d.substeps > 1) return;  // pieces that broke smoothness: BDF1 restart
  // The step began or ended all contact (IpcContactTerm::broke_smoothness): BDF2 would
  // extrapolate through that kink in a body's history, which adds energy. Only bodies in
  // contact at the step's start or end have one; if each of them now has the ballistic
  // history, no kink is left and BDF2 goes on. Another term's kink (a joint limit) restarts.
  for (const auto& t : terms_)
    if (t != contact_ && t->broke_smoothness()) return;
  std::vector<unsigned char> touched(n_, 0);
  mark_in_contact(forces, touched);
  mark_in_contact(contact_->contact_forces(step_q_t_), touched);
  for (int b = 0; b < n_; ++b)
    if (touched[b] && !restarted[b] && !fixed_[b] && !kinematic_[b]) return;
  has_history_ = true;
}

}  // namespace abd
