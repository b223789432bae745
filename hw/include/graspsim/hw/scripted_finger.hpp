// A finger moved by a script: the device reads its trajectory and keeps the last force it was
// asked to render (there is no hand to push back).
#pragma once

#include <memory>

#include "graspsim/hw/device.hpp"
#include "graspsim/hw/trajectory.hpp"

namespace graspsim::hw {

class ScriptedFinger final : public Device {
 public:
  ScriptedFinger(std::unique_ptr<Trajectory> trajectory, DeviceLimits limits);
  DeviceSample read(std::int64_t tick, double time) override;
  DeviceLimits limits() const override { return limits_; }
  std::string describe() const override { return "scripted"; }
  Workspace workspace() const override { return reach_box(kWorldReach); }   // world frame, no device
  const Vec3& last_force() const { return last_force_; }   // N, world: last rendered force

 protected:
  void output(const Vec3& force) override { last_force_ = force; }

 private:
  std::unique_ptr<Trajectory> trajectory_;
  DeviceLimits limits_;
  Vec3 last_force_{0.0, 0.0, 0.0};
};

}  // namespace graspsim::hw
