#include "contact/damping/restitution.h"

#include <algorithm>
#include <cmath>

#include "common/affine.h"

namespace abd::contact {
namespace {

// Fraction of v_in below which the approach counts as arrested (its kinetic energy is then
// below 1e-4 of the episode's).
constexpr double kArrested = 1e-2;

// Key with the ground (−1) second and otherwise the smaller body first; `flip` when the
// record's sides come the other way round (its normal then points from a to b).
std::pair<int, int> pair_key(const std::array<int, 2>& bodies, bool& flip) {
  int a = bodies[0], b = bodies[1];
  flip = false;
  if (a < 0 || (b >= 0 && b < a)) {
    std::swap(a, b);
    flip = true;
  }
  return {a, b};
}

Vec3 material_point(const VecX& q, int body, const Vec3& x) {
  if (body < 0) return x;
  const Vec12 qb = q.segment<12>(12 * body);
  return affine_A(qb).inverse() * (x - affine_p(qb));
}

// World position / velocity of a material point (the ground's points stay put).
Vec3 point_at(const VecX& q, int body, const Vec3& x_bar) {
  return body < 0 ? x_bar : affine_point(Vec12(q.segment<12>(12 * body)), x_bar);
}
Vec3 point_velocity(const VecX& q_dot, int body, const Vec3& x_bar) {
  return body < 0 ? Vec3::Zero() : affine_point(Vec12(q_dot.segment<12>(12 * body)), x_bar);
}

// A unit rigid impulse along n at a body's material point x̄: the change of its 12 velocity
// dofs (translation and rotation ω = I⁻¹ (r × n), I the world inertia about the centre) and
// its inverse effective mass 1/m + (r × n)ᵀ I⁻¹ (r × n).
struct RigidResponse {
  Vec12 dq_dot = Vec12::Zero();
  double w = 0.0;
};

RigidResponse rigid_response(const VecX& q, int body, const Vec3& x_bar, const Vec3& n,
                             const RestitutionLaw::InertiaOf& inertia) {
  RigidResponse out;
  if (body < 0) return out;
  const RestitutionLaw::Inertia in = inertia(body, q);
  if (!(in.mass > 0.0)) return out;
  const Vec12 qb = q.segment<12>(12 * body);
  const Mat3 A = affine_A(qb);
  const Mat3 S = A * in.second_moment * A.transpose();  // about the centre, world axes
  const Mat3 I = S.trace() * Mat3::Identity() - S;
  const Vec3 r = A * (x_bar - in.center);
  const Vec3 rn = r.cross(n);
  const Vec3 omega = I.ldlt().solve(rn);
  out.w = 1.0 / in.mass + rn.dot(omega);
  // Ȧ = [ω]× A; ṗ so that the centre moves with n/m: ṗ + Ȧ x̄_c = n/m.
  Mat3 wx;
  wx << 0.0, -omega.z(), omega.y(), omega.z(), 0.0, -omega.x(), -omega.y(), omega.x(), 0.0;
  const Mat3 A_dot = wx * A;
  out.dq_dot = q_from(A_dot, n / in.mass - A_dot * in.center);
  return out;
}

// The pair's response to a unit impulse +n on a and −n on b.
struct NormalDirection {
  Vec12 da = Vec12::Zero(), db = Vec12::Zero();
  double w = 0.0;
  bool dynamic_a = false, dynamic_b = false;
};

NormalDirection normal_direction(const VecX& q, int a, int b, const Vec3& xa, const Vec3& xb,
                                 const Vec3& n, const RestitutionLaw::InertiaOf& inertia) {
  const RigidResponse ra = rigid_response(q, a, xa, n, inertia);
  const RigidResponse rb = rigid_response(q, b, xb, n, inertia);
  NormalDirection d;
  d.da = ra.dq_dot;
  d.db = rb.dq_dot;
  d.w = ra.w + rb.w;
  d.dynamic_a = ra.w > 0.0;
  d.dynamic_b = rb.w > 0.0;
  return d;
}

// Mechanical energy of the pair's bodies at (q, q_dot) plus the pair's barrier energy.
double pair_energy(int a, int b, const VecX& q, const VecX& q_dot, double barrier,
                   const RestitutionLaw::InertiaOf& inertia) {
  double E = barrier;
  for (int body : {a, b}) {
    if (body < 0) continue;
    const RestitutionLaw::Inertia in = inertia(body, q);
    if (!(in.mass > 0.0)) continue;
    const Vec12 v = q_dot.segment<12>(12 * body);
    E += 0.5 * v.dot(in.mass_matrix * v) + in.potential;
  }
  return E;
}

}  // namespace

int RestitutionLaw::open_episodes() const {
  return int(std::count_if(episodes_.begin(), episodes_.end(),
                           [](const auto& kv) { return kv.second.applies; }));
}

int RestitutionLaw::after_step(const std::vector<ContactForce>& forces, const VecX& q_t,
                               const VecX& q_dot_t, const VecX& q, VecX& q_dot,
                               const Vec3& gravity, double threshold,
                               const RestitutionOf& restitution,
                               const InertiaOf& inertia) {
  // Force-weighted point and normal, and the barrier energy, per body pair at q.
  struct Sum {
    Vec3 point = Vec3::Zero(), normal = Vec3::Zero();
    double force = 0.0, energy = 0.0;
  };
  std::map<std::pair<int, int>, Sum> in_contact;
  for (const ContactForce& f : forces) {
    if (!(f.normal_force > 0.0)) continue;
    bool flip = false;
    const auto key = pair_key(f.bodies, flip);
    if (!(restitution(key.first, key.second) >= 0.0)) continue;
    Sum& s = in_contact[key];
    s.point += f.normal_force * f.point;
    s.normal += f.normal_force * (flip ? Vec3(-f.normal) : f.normal);
    s.force += f.normal_force;
    s.energy += f.energy;
  }
  int impulses = 0;
  // Sets the pair's relative normal velocity to `target` by one impulse along n, the impulse
  // limited to those that leave the bodies' energy (plus `barrier`) at most `cap`.
  auto set_normal_velocity = [&](int a, int b, const NormalDirection& d, double v_n,
                                 double target, double barrier, double cap) {
    if (!(d.w > 0.0) || target == v_n) return;
    double P = (target - v_n) / d.w;
    // E(P) = E0 + k1 P + k2 P² over the dynamic bodies.
    const double E0 = pair_energy(a, b, q, q_dot, barrier, inertia);
    double k1 = 0.0, k2 = 0.0;
    for (int side = 0; side < 2; ++side) {
      const int body = side == 0 ? a : b;
      if (body < 0) continue;
      const Inertia in = inertia(body, q);
      if (!(in.mass > 0.0)) continue;
      const Vec12 dv = side == 0 ? d.da : Vec12(-d.db);
      const Vec12 Mdv = in.mass_matrix * dv;
      k1 += q_dot.segment<12>(12 * body).dot(Mdv);
      k2 += 0.5 * dv.dot(Mdv);
    }
    const auto energy_at = [&](double p) { return E0 + p * (k1 + k2 * p); };
    if (energy_at(P) > cap && k2 > 0.0) {
      // The impulses whose energy is within the cap form [p1, p2] (empty: the one that
      // lowers the energy most); take the one nearest to P.
      const double disc = k1 * k1 - 4.0 * k2 * (E0 - cap);
      if (disc < 0.0) {
        P = -k1 / (2.0 * k2);
      } else {
        const double r = std::sqrt(disc);
        P = std::clamp(P, (-k1 - r) / (2.0 * k2), (-k1 + r) / (2.0 * k2));
      }
    }
    if (P == 0.0) return;
    q_dot.segment<12>(12 * a) += P * d.da;
    if (b >= 0) q_dot.segment<12>(12 * b) -= P * d.db;
    ++impulses;
  };
  // Gravity's work on the pair's normal motion over the step: m (n · Δg) times the normal
  // displacement of the contact's material points from q_t to q.
  auto gravity_work = [&](int a, int b, const Episode& ep, const NormalDirection& d) {
    const Vec3 dg = (d.dynamic_a ? gravity : Vec3::Zero()) - (d.dynamic_b ? gravity : Vec3::Zero());
    const double ds = ep.normal.dot((point_at(q, a, ep.x_bar_a) - point_at(q_t, a, ep.x_bar_a)) -
                                    (point_at(q, b, ep.x_bar_b) - point_at(q_t, b, ep.x_bar_b)));
    return ep.normal.dot(dg) * ds / d.w;
  };
  // The speed that leaves the pair with normal energy `budget` (T or e² T) given its barrier
  // energy and gravity's work.
  auto speed_for = [](double budget, const Episode& ep, double barrier, double w) {
    return std::sqrt(2.0 * w * std::max(0.0, budget + ep.work - barrier));
  };

  for (const auto& [key, s] : in_contact) {
    const double length = s.normal.norm();
    if (!(length > 0.0)) continue;
    const auto [a, b] = key;
    const Vec3 point = s.point / s.force;
    auto it = episodes_.find(key);
    const bool fresh = it == episodes_.end();
    Episode& ep = fresh ? episodes_[key] : it->second;
    if (fresh || ep.applies) {  // an inert episode keeps nothing up to date
      ep.normal = s.normal / length;
      ep.x_bar_a = material_point(q, a, point);
      ep.x_bar_b = material_point(q, b, point);
    }
    const NormalDirection d = normal_direction(q, a, b, ep.x_bar_a, ep.x_bar_b, ep.normal, inertia);
    if (fresh) {
      // The approach speed of these material points at the step start.
      ep.v_in = -ep.normal.dot(point_velocity(q_dot_t, a, ep.x_bar_a) -
                               point_velocity(q_dot_t, b, ep.x_bar_b));
      ep.e = restitution(a, b);
      ep.applies = ep.v_in > threshold && d.w > 0.0;
      // T: the normal energy the pair arrives with, gravity's work over this step included
      // (v_in is the speed at the step start, up to a step above the contact).
      ep.energy = ep.applies ? 0.5 * ep.v_in * ep.v_in / d.w + gravity_work(a, b, ep, d) : 0.0;
      ep.cap = pair_energy(a, b, q_t, q_dot_t, 0.0, inertia);
    } else if (ep.applies && !ep.restitution) {
      // Still compressing at the start of this step: gravity's work on the way down to the
      // turn is energy the impact absorbs, and only e² of it comes back, like T's (a sphere
      // dropped 5 cm at h = 1e-2 left at 1.02 e when it all came back).
      ep.energy += gravity_work(a, b, ep, d);
    } else if (ep.applies) {
      ep.work += gravity_work(a, b, ep, d);
    }
    if (!ep.applies) continue;
    const double v_n = ep.normal.dot(point_velocity(q_dot, a, ep.x_bar_a) -
                                     point_velocity(q_dot, b, ep.x_bar_b));
    if (ep.restitution && v_n < 0.0) {  // turned back inside d̂: the episode is over
      episodes_.erase(key);
      continue;
    }
    // The compression is over when the step arrested the approach: an implicit step that
    // stops the pair inside the barrier leaves a normal speed of round-off size, of either sign.
    ep.restitution = ep.restitution || v_n >= -kArrested * ep.v_in;
    const double budget = ep.restitution ? ep.e * ep.e * ep.energy : ep.energy;
    const double speed = speed_for(budget, ep, s.energy, d.w);
    const double cap = ep.cap - (ep.restitution ? (1.0 - ep.e * ep.e) * ep.energy : 0.0);
    set_normal_velocity(a, b, d, v_n, ep.restitution ? speed : -speed, s.energy, cap);
  }
  // Episodes whose pair left d̂: it separates with the restitution's energy (B = 0).
  for (auto it = episodes_.begin(); it != episodes_.end();) {
    if (in_contact.count(it->first)) {
      ++it;
      continue;
    }
    const auto [a, b] = it->first;
    Episode& ep = it->second;
    if (ep.applies) {
      const NormalDirection d = normal_direction(q, a, b, ep.x_bar_a, ep.x_bar_b, ep.normal, inertia);
      ep.work += gravity_work(a, b, ep, d);
      const double v_n = ep.normal.dot(point_velocity(q_dot, a, ep.x_bar_a) -
                                       point_velocity(q_dot, b, ep.x_bar_b));
      if (v_n > 0.0)
        set_normal_velocity(a, b, d, v_n, speed_for(ep.e * ep.e * ep.energy, ep, 0.0, d.w), 0.0,
                            ep.cap - (1.0 - ep.e * ep.e) * ep.energy);
    }
    it = episodes_.erase(it);
  }
  return impulses;
}

}  // namespace abd::contact
