// Which contact elements collide, and with what friction coefficient. Each body carries a
// contact element id (the ground has its own); a user rule over pairs of element ids says
// {enabled, μ}. The rule is called once per pair of distinct ids at construction (never
// during a step), with the smaller id first, so the table is symmetric by construction.
#pragma once
#include <functional>
#include <vector>

#include <Eigen/Core>

namespace abd::contact {

struct ContactRule {
  bool enabled = true;
  double mu = 0.5;
  double damping = -1.0;  // normal damping ratio ζ; < 0: the scene's default
  // coefficient of restitution e in [0, 1] (damping/restitution.h); < 0: the scene's default
  double restitution = -1.0;
};

using ContactRuleFn = std::function<ContactRule(int element_a, int element_b)>;

// A rule from square matrices over element ids: enabled(a, b) != 0, mu(a, b) and (if not
// empty) damping(a, b); ids outside the matrices collide with default_mu and the default ζ.
ContactRuleFn contact_rule_from_matrices(const Eigen::MatrixXi& enabled, const Eigen::MatrixXd& mu,
                                         double default_mu,
                                         const Eigen::MatrixXd& damping = Eigen::MatrixXd(),
                                         const Eigen::MatrixXd& restitution = Eigen::MatrixXd());

class ContactTable {
 public:
  ContactTable() = default;
  // body_element: one id per body (empty: all 0). An empty rule: every pair collides with
  // default_mu and default_damping (a rule's damping < 0 also means default_damping; the same
  // for restitution, whose default < 0 means none).
  ContactTable(int n_bodies, const std::vector<int>& body_element, int ground_element,
               double default_mu, const ContactRuleFn& rule, double default_damping = 0.0,
               double default_restitution = -1.0);

  const ContactRule& bodies(int a, int b) const { return rule(body_index_[a], body_index_[b]); }
  const ContactRule& ground(int b) const { return rule(body_index_[b], ground_index_); }
  // Whether some pair has a restitution (>= 0).
  bool any_restitution() const { return any_restitution_; }

 private:
  const ContactRule& rule(int i, int j) const { return rules_[i * n_ + j]; }
  int n_ = 0;                     // distinct element ids in use
  std::vector<ContactRule> rules_;  // n_ × n_, over dense indices of the ids
  std::vector<int> body_index_;
  int ground_index_ = 0;
  bool any_restitution_ = false;
};

}  // namespace abd::contact
