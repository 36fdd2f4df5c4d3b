// Additive CCD (ACCD; Li, Kaufman, Jiang, "Codimensional Incremental Potential Contact", 2021)
// for primitives whose vertices move linearly from x(0) to x(1) — exactly ABD's case, since
// x(α) = J(x̄)(q + α Δq) is linear in α.
//
// ACCD never computes a root. It advances t by steps that are provably safe: with l_p an upper
// bound on how fast the gap g = d − ξ can shrink (sum of the two primitives' largest vertex
// displacements, after removing their common mean motion), a step of 0.9 g / l_p can close at
// most 90% of the remaining gap. It stops once the gap falls below `target` × its initial value,
// returning the last time whose configuration kept that margin. The result is therefore
// conservative (never beyond the true time of impact) and leaves a gap, which is the safety
// factor that keeps the line search short of contact.
//
// Return value: t in [0, tmax]; tmax means no impact before tmax; 0 when the primitives start
// at or inside the minimum separation.
#pragma once
#include "common/types.h"

namespace abd::contact {

struct CcdOptions {
  double min_distance = 0.0;   // ξ: the primitives must stay farther apart than this
  double tmax = 1.0;
  double target = 0.1;         // s: keep at least s × the initial gap
  long max_iterations = 10000;  // a cap for grazing motion; the t reached so far is safe
  // If set, receives the gap d − ξ at t = 0 whenever the primitives move (a caller that also
  // needs it, swept_reach.h, saves a distance); left as it is otherwise.
  double* start_gap = nullptr;
  // If set, receives with start_gap the bound on how fast each side closes the gap: the
  // largest vertex move of the first primitive's and of the second's after removing their
  // mean move, and the length of that mean (what swept_reach.h's bound takes).
  struct Moves {
    double first = 0.0, second = 0.0, common = 0.0;
  };
  Moves* moves = nullptr;
};

double point_point_ccd(const Vec3& p0_t0, const Vec3& p1_t0, const Vec3& p0_t1,
                       const Vec3& p1_t1, const CcdOptions& options = {});

double point_edge_ccd(const Vec3& p_t0, const Vec3& e0_t0, const Vec3& e1_t0, const Vec3& p_t1,
                      const Vec3& e0_t1, const Vec3& e1_t1, const CcdOptions& options = {});

double point_triangle_ccd(const Vec3& p_t0, const Vec3& t0_t0, const Vec3& t1_t0,
                          const Vec3& t2_t0, const Vec3& p_t1, const Vec3& t0_t1,
                          const Vec3& t1_t1, const Vec3& t2_t1, const CcdOptions& options = {});

double edge_edge_ccd(const Vec3& ea0_t0, const Vec3& ea1_t0, const Vec3& eb0_t0,
                     const Vec3& eb1_t0, const Vec3& ea0_t1, const Vec3& ea1_t1,
                     const Vec3& eb0_t1, const Vec3& eb1_t1, const CcdOptions& options = {});

}  // namespace abd::contact
