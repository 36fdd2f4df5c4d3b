// The largest violation over a set of joints, without a square root or an atan2 per joint:
// distances are compared squared and angles atan2(y, x) (y = |a × b| >= 0) by the sign of
// sin(θ_new − θ_old) ∝ y_new x_old − x_new y_old; result() takes the one square root and the
// one atan2 of the worst. sqrt is monotone, so the distance has the bits of the largest norm;
// the angle those of the largest atan2 up to the rounding of the products compared (angles
// within an ulp or so of each other).
#pragma once
#include <algorithm>
#include <cmath>

#include "common/types.h"
#include "solver/constraint.h"

namespace abd {

struct WorstViolation {
  double position_squared = 0.0;
  double y = 0.0, x = 1.0;  // the worst angle so far as atan2(y, x); none yet: 0

  void add_distance_squared(double d2) { position_squared = std::max(position_squared, d2); }
  // The angle between directions a and b.
  void add_angle(const Vec3& a, const Vec3& b) {
    const double y_new = a.cross(b).norm(), x_new = a.dot(b);
    const double s = y_new * x - x_new * y;
    // s == 0: the same angle, or 0 against π (antiparallel, y = 0 and x < 0).
    if (s > 0.0 || (s == 0.0 && x_new < 0.0 && x > 0.0)) {
      y = y_new;
      x = x_new;
    }
  }
  ConstraintViolation result() const {
    return {std::sqrt(position_squared), std::atan2(y, x)};
  }
};

}  // namespace abd
