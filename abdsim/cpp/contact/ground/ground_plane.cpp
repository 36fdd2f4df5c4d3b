#include "contact/ground/ground_plane.h"

namespace abd::contact {

double point_ground_ccd(const Vec3& p_t0, const Vec3& p_t1, double height,
                        const CcdOptions& options) {
  const double gap0 = p_t0.z() - height - options.min_distance;
  if (!(gap0 > 0.0)) return 0.0;
  const double dz = p_t1.z() - p_t0.z();
  if (dz >= 0.0) return options.tmax;
  const double toi = gap0 / -dz;  // exact time the gap closes
  if (toi > options.tmax) return options.tmax;
  return (1.0 - options.target) * toi;
}

}  // namespace abd::contact
