#include "energy/shape_energy.h"

#include <stdexcept>
#include <string>

#include "common/affine.h"
#include "energy/arap.h"
#include "energy/ortho_potential.h"

namespace abd {
namespace {
void check_uid(int uid) {
  if (uid != kOrthoPotential && uid != kARAP)
    throw std::invalid_argument("unknown constitution_uid " + std::to_string(uid) +
                                " (1 = OrthoPotential, 2 = ARAP)");
}
}  // namespace

double shape_energy_value(int uid, const Vec12& q, double kappa, double volume) {
  check_uid(uid);
  const Mat3 A = affine_A(q);
  const double psi = uid == kOrthoPotential ? ortho_potential(A) : arap(A);
  return kappa * volume * psi;
}

ShapeEnergyResult shape_energy(int uid, const Vec12& q, double kappa, double volume,
                               bool project_psd, bool want_hessian, double absorb) {
  check_uid(uid);
  const Mat3 A = affine_A(q);
  const double w = kappa * volume;
  ShapeEnergyResult r;
  if (uid == kOrthoPotential) {
    r.value = w * ortho_potential_add_body_derivatives(A, project_psd, w, r.gradient,
                                                       want_hessian ? &r.hessian : nullptr, absorb);
  } else {
    r.value = w * arap(A);
    r.gradient.tail<9>() = w * arap_gradient(A);
    if (want_hessian) r.hessian.bottomRightCorner<9, 9>() = w * arap_hessian(A, project_psd);
  }
  return r;
}

}  // namespace abd
