#include "joints/body_wrench_term.h"

#include <stdexcept>
#include <string>

#include "common/affine.h"

namespace abd {

void BodyWrenchTerm::set_wrench(int body, const Vec3& force, const Vec3& torque,
                                const Vec3& x_bar) {
  if (body < 0 || body >= n_)
    throw std::out_of_range("apply_wrench: body index " + std::to_string(body) +
                            " out of range [0, " + std::to_string(n_) + ")");
  if (!force.allFinite() || !torque.allFinite() || !x_bar.allFinite())
    throw std::invalid_argument("apply_wrench: body " + std::to_string(body) +
                                ": force, torque and point must be finite");
  for (Wrench& w : wrenches_)
    if (w.body == body) {
      w.force = force;
      w.torque = torque;
      w.x_bar = x_bar;
      return;
    }
  wrenches_.push_back({body, force, torque, x_bar});
}

void BodyWrenchTerm::clear() { wrenches_.clear(); }

void BodyWrenchTerm::begin_step(const StepContext& ctx) {
  for (Wrench& w : wrenches_) {
    w.A_t = affine_A(ctx.q_t.segment<12>(12 * w.body));
    w.A_t_inv = w.A_t.inverse();
  }
}

// E = −F·(A x̄ + p) − τ·vee(skew((A − A_t) A_t⁻¹)); with B = A_t⁻¹, the torque part is
// −½ Σ τ_k ε_kij (A B)_ij, linear in the rows a_i: ∂/∂a_i = −½ Σ_kj τ_k ε_kij B_{·j}.
Vec12 BodyWrenchTerm::gradient_of(const Wrench& w) const {
  Vec12 g = Vec12::Zero();
  g.head<3>() = -w.force;
  for (int i = 0; i < 3; ++i) g.segment<3>(3 + 3 * i) = -w.force[i] * w.x_bar;
  const Mat3& B = w.A_t_inv;
  // vee(skew(M)) = ½ (M21 − M12, M02 − M20, M10 − M01); M = A B, M_ij = a_i·B_{·j}.
  const int idx[3][2] = {{2, 1}, {0, 2}, {1, 0}};
  for (int k = 0; k < 3; ++k) {
    const int i = idx[k][0], j = idx[k][1];
    g.segment<3>(3 + 3 * i) -= 0.5 * w.torque[k] * B.col(j);
    g.segment<3>(3 + 3 * j) += 0.5 * w.torque[k] * B.col(i);
  }
  return g;
}

double BodyWrenchTerm::value(const VecX& q) const {
  double E = 0.0;
  for (const Wrench& w : wrenches_) {
    Vec12 dq = q.segment<12>(12 * w.body);
    dq.tail<9>() -= q_from(w.A_t, Vec3::Zero()).tail<9>();  // measured from A_t (linear)
    E += gradient_of(w).dot(dq);
  }
  return E;
}

void BodyWrenchTerm::add_gradient(const VecX&, double scale, VecX& gradient) const {
  for (const Wrench& w : wrenches_) gradient.segment<12>(12 * w.body) += scale * gradient_of(w);
}

void BodyWrenchTerm::add_body_values(const VecX& q, const std::vector<unsigned char>& movable,
                                     VecX& per_body, std::vector<BodyLink>&) const {
  for (const Wrench& w : wrenches_) {
    if (!movable[w.body]) continue;
    Vec12 dq = q.segment<12>(12 * w.body);
    dq.tail<9>() -= q_from(w.A_t, Vec3::Zero()).tail<9>();
    per_body[w.body] += gradient_of(w).dot(dq);
  }
}

void BodyWrenchTerm::body_max_steps(const VecX&, const VecX&, const std::vector<unsigned char>&,
                                    VecX&, std::vector<unsigned char>& near,
                                    std::vector<BodyLink>&) const {
  for (const Wrench& w : wrenches_) near[w.body] = 1;
}

void BodyWrenchTerm::mark_forced_bodies(std::vector<unsigned char>& flags) const {
  for (const Wrench& w : wrenches_) flags[size_t(w.body)] = 1;
}

}  // namespace abd
