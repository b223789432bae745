// Workspaces shared by every device.
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


}  // namespace graspsim::hw
