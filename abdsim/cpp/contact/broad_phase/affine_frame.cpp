#include "contact/broad_phase/affine_frame.h"

#include <algorithm>
#include <cmath>

namespace abd::contact {
namespace {

// Below this shape quality |det E| / (|e1| |e2| |e3|) (1 for orthogonal edges), or this height
// over the diameter, the tetrahedron is too flat for a well-conditioned recovery: the body is
// refit instead. The recovery's error then stays below ~1e4 ε |x| ≪ the slack below.
constexpr double kMinQuality = 1e-3;
constexpr double kMinHeight = 1e-4;
// Relative slack added to every recovered box: far above the rounding of a recovery (about
// 1e-12 |x| at the conditioning allowed above), far below any contact distance of interest.
constexpr double kRelativePad = 1e-9;

template <class Distance>
int farthest(const std::vector<Vec3>& v, const Distance& distance) {
  int best = 0;
  double d_best = -1.0;
  for (int i = 0; i < int(v.size()); ++i) {
    const double d = distance(v[size_t(i)]);
    if (d > d_best) best = i, d_best = d;
  }
  return best;
}

}  // namespace

AffineFrame::AffineFrame(const std::vector<Vec3>& rest) {
  if (rest.size() < 4) return;
  Vec3 centre = Vec3::Zero();
  for (const Vec3& x : rest) centre += x;
  centre /= double(rest.size());
  const int i0 = farthest(rest, [&](const Vec3& x) { return (x - centre).squaredNorm(); });
  const Vec3 a = rest[size_t(i0)];
  const int i1 = farthest(rest, [&](const Vec3& x) { return (x - a).squaredNorm(); });
  const Vec3 e1 = rest[size_t(i1)] - a;
  const double diameter = e1.norm();
  if (!(diameter > 0.0)) return;
  const Vec3 u = e1 / diameter;
  const int i2 = farthest(rest, [&](const Vec3& x) { return (x - a - u * u.dot(x - a)).norm(); });
  const Vec3 e2 = rest[size_t(i2)] - a;
  const Vec3 n = e1.cross(e2);
  if (!(n.norm() > 0.0)) return;
  const Vec3 nu = n.normalized();
  const int i3 = farthest(rest, [&](const Vec3& x) { return std::abs(nu.dot(x - a)); });
  const Vec3 e3 = rest[size_t(i3)] - a;
  Mat3 E;
  E << e1, e2, e3;
  const double quality = std::abs(E.determinant()) / (e1.norm() * e2.norm() * e3.norm());
  if (!(quality >= kMinQuality) || !(std::abs(nu.dot(e3)) >= kMinHeight * diameter)) return;
  ref_ = {i0, i1, i2, i3};
  inv_edges_ = E.inverse();
  rest_ref0_ = a;
  for (const Vec3& x : rest) rest_radius_ = std::max(rest_radius_, (x - a).norm());
  // The extremes along each rest axis: a non-affine deformation shows there first.
  for (int k = 0; k < 3; ++k) {
    checks_.push_back(farthest(rest, [&](const Vec3& x) { return x[k]; }));
    checks_.push_back(farthest(rest, [&](const Vec3& x) { return -x[k]; }));
  }
  std::sort(checks_.begin(), checks_.end());
  checks_.erase(std::unique(checks_.begin(), checks_.end()), checks_.end());
  for (int i : checks_) rest_checks_.push_back(rest[size_t(i)]);
  valid_ = true;
}

bool AffineFrame::recover(const Vec3* x, AffineMap& out) const {
  if (!valid_) return false;
  const Vec3& x0 = x[ref_[0]];
  Mat3 X;
  X << x[ref_[1]] - x0, x[ref_[2]] - x0, x[ref_[3]] - x0;
  out.A = X * inv_edges_;
  out.p = x0 - out.A * rest_ref0_;
  const double scale = x0.cwiseAbs().maxCoeff() + out.A.cwiseAbs().maxCoeff() * rest_radius_;
  out.pad = kRelativePad * (scale + 1e-3);  // + 1 µm floor: bodies near the origin
  for (size_t k = 0; k < checks_.size(); ++k)
    if (!((x[checks_[k]] - (out.A * rest_checks_[k] + out.p)).cwiseAbs().maxCoeff() <= out.pad))
      return false;
  return true;
}

}  // namespace abd::contact
