// The World's built-in IPC contact: building the term from the scene, and what a step
// reports about it.
#include <limits>
#include <stdexcept>

#include "contact/ipc_contact_term.h"
#include "solver/world.h"

namespace abd {

IpcContactTerm& World::enable_contact(const ContactSettings& settings) {
  if (contact_) throw std::invalid_argument("enable_contact: contact is already enabled");
  SceneData scene = scene_;
  for (int b = 0; b < n_; ++b) scene.bodies[b].q = q_.segment<12>(12 * b);
  auto term = std::make_shared<IpcContactTerm>(scene, settings);
  for (int b = 0; b < n_; ++b) term->set_scripted(b, kinematic_[b] != 0);
  term->set_threads(threads_);
  term->check_initial(q_);
  contact_ = term;
  add_term(term);
  return *contact_;
}

double World::min_contact_distance(double max_distance) const {
  if (!contact_) return std::numeric_limits<double>::infinity();
  return contact_->min_distance(q_, max_distance);
}

void World::contact_diagnostics(StepDiagnostics& d) const {
  if (!contact_) return;
  const ContactCounts c = contact_->counts();
  d.contact_point_triangle = c.point_triangle;
  d.contact_edge_edge = c.edge_edge;
  d.contact_point_ground = c.point_ground;
  d.contact_friction = c.friction;
  d.min_contact_distance = contact_->min_distance(x_);
  d.contact_kappa = contact_->kappa();
}

}  // namespace abd
