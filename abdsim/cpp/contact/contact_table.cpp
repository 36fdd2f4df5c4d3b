#include "contact/contact_table.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace abd::contact {

ContactRuleFn contact_rule_from_matrices(const Eigen::MatrixXi& enabled, const Eigen::MatrixXd& mu,
                                         double default_mu, const Eigen::MatrixXd& damping,
                                         const Eigen::MatrixXd& restitution) {
  if (enabled.rows() != enabled.cols() || mu.rows() != enabled.rows() || mu.cols() != enabled.cols())
    throw std::invalid_argument("contact table: enabled and mu must be square and of equal size");
  if (damping.size() && (damping.rows() != enabled.rows() || damping.cols() != enabled.cols()))
    throw std::invalid_argument("contact table: damping must have the size of enabled");
  if (restitution.size() &&
      (restitution.rows() != enabled.rows() || restitution.cols() != enabled.cols()))
    throw std::invalid_argument("contact table: restitution must have the size of enabled");
  return [enabled, mu, default_mu, damping, restitution](int a, int b) {
    if (a >= enabled.rows() || b >= enabled.rows()) return ContactRule{true, default_mu, -1.0};
    return ContactRule{enabled(a, b) != 0, mu(a, b), damping.size() ? damping(a, b) : -1.0,
                       restitution.size() ? restitution(a, b) : -1.0};
  };
}

ContactTable::ContactTable(int n_bodies, const std::vector<int>& body_element, int ground_element,
                           double default_mu, const ContactRuleFn& rule_fn,
                           double default_damping, double default_restitution) {
  if (!body_element.empty() && int(body_element.size()) != n_bodies)
    throw std::invalid_argument("contact elements: " + std::to_string(body_element.size()) +
                                " ids for " + std::to_string(n_bodies) + " bodies");
  std::vector<int> ids(body_element);
  if (ids.empty()) ids.assign(n_bodies, 0);
  ids.push_back(ground_element);
  for (int id : ids)
    if (id < 0) throw std::invalid_argument("contact element ids must be >= 0");
  // Dense indices over the distinct ids keep the table small whatever the ids are.
  std::vector<int> distinct(ids);
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  auto index_of = [&](int id) {
    return int(std::lower_bound(distinct.begin(), distinct.end(), id) - distinct.begin());
  };
  n_ = int(distinct.size());
  if (!(default_damping >= 0.0) || !std::isfinite(default_damping))
    throw std::invalid_argument("contact table: damping must be finite and >= 0");
  if (!std::isfinite(default_restitution) || default_restitution > 1.0)
    throw std::invalid_argument("contact table: restitution must be in [0, 1] (< 0: none)");
  const double e0 = default_restitution >= 0.0 ? default_restitution : -1.0;
  rules_.assign(size_t(n_) * n_, ContactRule{true, default_mu, default_damping, e0});
  if (rule_fn)
    for (int i = 0; i < n_; ++i)
      for (int j = i; j < n_; ++j) {
        ContactRule r = rule_fn(distinct[i], distinct[j]);
        if (!(r.mu >= 0.0)) throw std::invalid_argument("contact table: friction mu must be >= 0");
        if (!std::isfinite(r.damping))
          throw std::invalid_argument("contact table: damping must be finite");
        if (r.damping < 0.0) r.damping = default_damping;
        if (!std::isfinite(r.restitution) || r.restitution > 1.0)
          throw std::invalid_argument("contact table: restitution must be in [0, 1]");
        if (r.restitution < 0.0) r.restitution = e0;
        rules_[i * n_ + j] = rules_[j * n_ + i] = r;
      }
  for (int b = 0; b < n_bodies; ++b) body_index_.push_back(index_of(ids[b]));
  for (const ContactRule& r : rules_) any_restitution_ = any_restitution_ || r.restitution >= 0.0;
  ground_index_ = index_of(ground_element);
}

}  // namespace abd::contact
