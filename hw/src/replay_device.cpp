// Recorded samples, row by row.
#include "graspsim/hw/replay_device.hpp"

#include <stdexcept>
#include <utility>

namespace graspsim::hw {

ReplayDevice::ReplayDevice(std::vector<Vec3> positions, std::vector<Vec3> gimbals, DeviceLimits limits,
                           std::string source, std::unique_ptr<Trajectory> script)
    : positions_(std::move(positions)),
      gimbals_(std::move(gimbals)),
      limits_(limits),
      source_(std::move(source)),
      script_(std::move(script)) {
  if (positions_.size() != gimbals_.size()) {
    throw std::invalid_argument("ReplayDevice (" + source_ + "): " + std::to_string(positions_.size()) +
                                " positions but " + std::to_string(gimbals_.size()) + " gimbal samples");
  }
}

DeviceSample ReplayDevice::read(std::int64_t tick, double time) {
  if (tick < 0 || tick >= ticks()) {
    throw std::out_of_range("replay of " + source_ + ": no recorded sample for servo tick " + std::to_string(tick) +
                            " (the recording holds ticks 0 to " + std::to_string(ticks() - 1) + ")");
  }
  if (script_) script_->sample(time);   // for what the script keeps; its motion is not used
  DeviceSample s;
  s.position = positions_[static_cast<std::size_t>(tick)];
  s.gimbal = gimbals_[static_cast<std::size_t>(tick)];
  return s;
}

}  // namespace graspsim::hw
