// The gate between a device and the engine: every sample, from every source (a replayed trace, a
// UDP peer, a simulated or real Phantom, a script), is checked before the engine sees it. A
// position or gimbal angle that is not finite, or a position outside the device's workspace
// (Device::workspace(), in the device's own frame), is refused with a message naming the
// finger, the device and the tick; the run loop then stops the run with that error (exit 2, the
// trace kept up to the tick before, status "error: ..."). hw/README.md, "Sample checks".
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "graspsim/hw/device.hpp"


namespace graspsim::hw {

class BadSample : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class SampleCheck {
 public:
  // `device` must outlive the check; `finger` is the finger's name, for messages. A mapped device
  // is checked in its own frame (the sample before the mapping) and in the world.
  SampleCheck(const Device& device, std::string finger);
  // Throws BadSample when `world` (the sample read at servo tick `tick`, time `time` s) is not
  // finite or lies outside the workspace. Allocates nothing when the sample is good.
  void check(const DeviceSample& world, std::int64_t tick, double time) const;

 private:
  [[noreturn]] void refuse(std::int64_t tick, double time, const std::string& what) const;

  const Device& device_;
  bool mapped_ = false;   // its frame is not the world (Device::device_frame_sample)
  Workspace workspace_;                    // m, the device's own frame
  std::string finger_;
};

}  // namespace graspsim::hw
