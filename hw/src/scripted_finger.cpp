// A scripted finger: the HIP follows a trajectory; forces are kept, not felt.
#include "graspsim/hw/scripted_finger.hpp"

#include <stdexcept>

namespace graspsim::hw {

ScriptedFinger::ScriptedFinger(std::unique_ptr<Trajectory> trajectory, DeviceLimits limits)
    : trajectory_(std::move(trajectory)), limits_(limits) {
  if (!trajectory_) throw std::invalid_argument("scripted finger: no trajectory");
}

DeviceSample ScriptedFinger::read(std::int64_t /*tick*/, double time) {
  const TrajectorySample t = trajectory_->sample(time);
  DeviceSample s;
  s.position = t.position;
  s.gimbal = t.gimbal;
  return s;
}

}  // namespace graspsim::hw
