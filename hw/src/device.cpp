// Force safety and workspaces shared by every device.
#include "graspsim/hw/device.hpp"

#include <cmath>
#include <limits>

namespace graspsim::hw {

bool Workspace::contains(const Vec3& p) const {
  for (int i = 0; i < 3; ++i)
    if (!(p[i] >= min[i] && p[i] <= max[i])) return false;
  return true;
}

Workspace reach_box(double half_side) { return Workspace{Vec3::Constant(-half_side), Vec3::Constant(half_side)}; }

Vec3 clamp_force(const Vec3& force, const DeviceLimits& limits) {
  const double limit = limits.max_force;
  if (!force.allFinite() || !(limit > 0.0)) return Vec3::Zero();   // a fault renders nothing
  if (std::isinf(limit)) return force;
  // Work on force / s with s its largest component: |u| lies in [1, sqrt 3], so no square
  // overflows (forces up to DBL_MAX) or underflows (limits down to the smallest doubles).
  const double s = force.cwiseAbs().maxCoeff();
  if (s == 0.0) return force;
  const Vec3 u = force / s;
  const double u_norm = u.norm();
  if (s <= limit / u_norm && force.norm() <= limit) return force;   // within: unchanged
  // Along the same direction, 4 ulp short of the limit, so that no way of computing the norm
  // (any summation order, with or without extended precision) finds it above the limit.
  constexpr double kShrink = 1.0 - 4.0 * std::numeric_limits<double>::epsilon();
  return u * (limit / u_norm * kShrink);
}

}  // namespace graspsim::hw
