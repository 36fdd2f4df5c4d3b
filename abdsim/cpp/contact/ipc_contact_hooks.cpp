// IpcContactTerm's answers to the solver's generic hooks (solver/energy_term.h): what the
// Newton loop needs from contact without knowing it is contact.
#include <algorithm>

#include "contact/ipc_contact_term.h"

namespace abd {

// Static friction is a spring of stiffness μλ / (ε_v h): a force it cannot hold moves a Newton
// step of only ~ε_v h before the contact slides, so below ε_v in velocity units a step
// tolerance cannot tell sticking from the onset of sliding. Bodies with lagged friction (or
// damping) this step converge to 0.1 ε_v (translation) and 0.1 ε_v / radius (affine) at most.
void IpcContactTerm::limit_tolerances(VecX& tol_translation, VecX& tol_affine,
                                      const std::vector<double>& radius) const {
  std::vector<unsigned char> rubbing(static_cast<std::size_t>(tol_translation.size()), 0);
  mark_friction_bodies(rubbing);
  const double tol = 0.1 * settings_.eps_v;
  for (std::size_t b = 0; b < rubbing.size(); ++b)
    if (rubbing[b]) {
      tol_translation[b] = std::min(tol_translation[b], tol);
      tol_affine[b] = std::min(tol_affine[b], tol / radius[b]);
    }
}

void IpcContactTerm::mark_lagged_bodies(std::vector<unsigned char>& flags) const {
  mark_friction_bodies(flags);
}

bool IpcContactTerm::balances_stiffness() const {
  if (!adaptive_kappa()) return false;
  const ContactCounts c = counts();
  return c.point_triangle + c.edge_edge + c.point_ground > 0;
}

void IpcContactTerm::balance_stiffness(const VecX& q, const VecX& grad_rest) {
  initialize_kappa(q, grad_rest);
}

}  // namespace abd
