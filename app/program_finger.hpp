// A finger moved by the program that steps the run (RunSession: the Python module, an embedding
// application), as a device would be. It follows the finger's scenario trajectory until the
// program sets a HIP; from then it gives that HIP at every read until the program sets another
// or hands the finger back to its trajectory. The trajectory is sampled at every tick either
// way, as the run does for a device that does not run the finger's script
// (RunOptions::Devices::script_alongside), so a script that keeps state sees the same ticks
// whoever drives the finger.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "graspsim/engine/math.hpp"
#include "graspsim/hw/device.hpp"
#include "graspsim/hw/trajectory.hpp"

namespace graspsim::app {

class ProgramFinger final : public hw::Device {
 public:
  ProgramFinger(std::unique_ptr<hw::Trajectory> trajectory, hw::DeviceLimits limits)
      : trajectory_(std::move(trajectory)), limits_(limits) {}

  // The HIP (m, world) and gimbal angles (rad: roll, pitch, yaw) from the next read on. Throws
  // std::invalid_argument for a value that is not finite (the run's sample check would stop
  // the run on it).
  void set(const Vec3& hip, const Vec3& gimbal) {
    if (!hip.allFinite()) throw std::invalid_argument("a HIP must be finite (m, world)");
    if (!gimbal.allFinite()) throw std::invalid_argument("gimbal angles must be finite (rad)");
    sample_.position = hip;
    sample_.gimbal = gimbal;
    held_ = true;
  }
  void follow_trajectory() { held_ = false; }   // the scenario's trajectory again from the next read
  bool held() const { return held_; }
  const hw::DeviceSample& sample() const { return sample_; }   // the last read (or set) sample
  const Vec3& last_force() const { return last_force_; }        // N, world: last rendered (clamped)

  hw::DeviceSample read(std::int64_t, double time) override {
    const hw::TrajectorySample s = trajectory_->sample(time);
    if (!held_) {
      sample_.position = s.position;
      sample_.gimbal = s.gimbal;
    }
    return sample_;
  }
  hw::DeviceLimits limits() const override { return limits_; }
  std::string describe() const override { return "program (its HIP set by the program stepping the run)"; }
  hw::Workspace workspace() const override { return hw::reach_box(hw::kWorldReach); }   // world frame

 protected:
  void output(const Vec3& force) override { last_force_ = force; }

 private:
  std::unique_ptr<hw::Trajectory> trajectory_;
  hw::DeviceLimits limits_;
  hw::DeviceSample sample_;
  bool held_ = false;
  Vec3 last_force_{0.0, 0.0, 0.0};
};

}  // namespace graspsim::app
