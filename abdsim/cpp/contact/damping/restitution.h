// A coefficient of restitution e for contact pairs: Stronge's energetic law on the pair's
// normal motion, held through the steps a pair spends inside the barrier (docs/restitution.md).
//
// Why not a term of Π: the implicit step itself dissipates most of an impact (IPC's barrier
// is far stiffer than a step resolves: undamped, a BDF1 drop rebounds with e ≤ 0.05, BDF2
// with e ≈ 0.2–0.3), so no dissipative term can give e = 0.5 or 0.9, and the trapezoidal
// rule, which has no numerical damping for linear forces, is not energy-conserving through
// a barrier either (measured: a 5 cm box drop at h = 1e-3 lost 37 % of its energy entering
// d̂ and the same steps gained energy elsewhere).
//
// The law: a pair (two bodies, or a body and the ground) that comes within d̂ with normal
// approach speed v_in > threshold starts an episode with the normal energy T = ½ m v_in² (m
// the pair's rigid effective mass along the normal at its contact point, v_in at the start
// of the step that brought it in, plus gravity's work over that step and every later step
// that begins in compression: the energy the impact absorbs down to the turn). The
// pair's normal energy is N = ½ m v_n² + B + W: its relative normal kinetic energy at the
// contact point, its barrier energy B, and the work W of gravity on its normal motion after
// the turn. After
// every step of the episode, one impulse along the normal at the contact point sets v_n so
// that N = T while the pair approaches (compression) and N = e² T once the step left it
// separating (restitution); when the pair leaves d̂ (B = 0) it separates at e v_in (plus
// gravity's work). The step's own numerical loss inside the barrier is thereby given back
// to the normal motion, and the only loss the episode keeps is Newton's (1 − e²) T. A pair
// that turns back inside d̂ during restitution ends its episode (a slow touch after it is
// the integrator's: resting contact comes to rest). The impulses change velocities only,
// never positions, so the barrier and CCD keep every step intersection-free.
#pragma once
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "common/types.h"
#include "contact/contact_force.h"

namespace abd::contact {

class RestitutionLaw {
 public:
  // e(a, b) of a body pair (b = −1: the ground); < 0: none (the pair is left alone).
  using RestitutionOf = std::function<double(int a, int b)>;
  // A body's rigid inertia in its material frame: mass (0 for bodies the dynamics does not
  // move: fixed, scripted), centre of mass x̄_c and central second moment Σ m (x̄ − x̄_c)(x̄ − x̄_c)ᵀ.
  // Impulses are rigid (a translation and a rotation): through an affine body's full 12x12
  // mass an impulse below the centre also stretches the body, and the stiff shape energy
  // then dissipates that share (a flat box would keep a quarter of the energy).
  // `mass_matrix` and `potential` (gravity's and the shape energy at the body's state) give
  // the body's mechanical energy, which caps the law (see after_step).
  struct Inertia {
    double mass = 0.0;
    Vec3 center = Vec3::Zero();
    Mat3 second_moment = Mat3::Zero();
    Mat12 mass_matrix = Mat12::Zero();
    double potential = 0.0;
  };
  // A body's inertia at the state q (body < 0 never asked).
  using InertiaOf = std::function<Inertia(int body, const VecX& q)>;

  // After a committed step from (q_t, q_dot_t) to (q, q_dot): `forces` are the contact
  // records at q (each with its barrier energy); episodes open, go on or end and q_dot gets
  // their impulses. Each impulse is capped so that the mechanical energy of the pair's bodies
  // (kinetic, gravity, shape, the pair's barrier) stays at most what it was when the episode
  // began, less (1 − e²) T once it separates: the law gives back the step's numerical loss,
  // never more (the normal bookkeeping alone misses the energy the impact puts into the
  // bodies' deformation). Returns the number of impulses applied.
  int after_step(const std::vector<ContactForce>& forces, const VecX& q_t, const VecX& q_dot_t,
                 const VecX& q, VecX& q_dot, const Vec3& gravity, double threshold,
                 const RestitutionOf& restitution, const InertiaOf& inertia);
  // Forgets every episode (a new state was set).
  void reset() { episodes_.clear(); }
  // Episodes open now (pairs in contact that came in faster than the threshold).
  int open_episodes() const;

 private:
  struct Episode {
    Vec3 x_bar_a = Vec3::Zero(), x_bar_b = Vec3::Zero();  // material points of the contact
    Vec3 normal = Vec3::UnitZ();                          // world, from b towards a
    double v_in = 0.0;         // normal approach speed (> 0)
    double energy = 0.0;       // T = ½ m v_in² + gravity's work down to the turn
    double work = 0.0;         // W: gravity's work on the normal motion after the turn
    double e = 0.0;
    double cap = 0.0;          // the bodies' mechanical energy at the start of the episode
    bool applies = false;      // came in faster than the threshold
    bool restitution = false;  // past the compression
  };
  std::map<std::pair<int, int>, Episode> episodes_;
};

}  // namespace abd::contact
