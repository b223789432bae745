// A finger fed from recorded device samples (a trace's /servo hip and gimbal): row n is the
// sample of servo tick n. The samples are an in-memory table; reading the trace that holds
// them is the caller's job (app/replay.cpp), so hw/ needs no HDF5.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "graspsim/hw/device.hpp"
#include "graspsim/hw/trajectory.hpp"

namespace graspsim::hw {

class ReplayDevice final : public Device {
 public:
  // positions[n] (m, world) and gimbals[n] (rad: roll, pitch, yaw) are the samples of servo
  // tick n; both the same length. `source` says where they came from (for describe()).
  // `script`, if given, is the finger's own trajectory: it is still evaluated at every read, as
  // in the recorded run, and its output discarded, so that a script which watches the run (a
  // Lua function reading the simulation view and keeping what it saw for the expectations)
  // sees the replay as it saw the original. Throws std::invalid_argument when the lengths differ.
  ReplayDevice(std::vector<Vec3> positions, std::vector<Vec3> gimbals, DeviceLimits limits,
               std::string source, std::unique_ptr<Trajectory> script = nullptr);
  // The recorded sample of `tick`, bit for bit; throws std::out_of_range naming the tick and the
  // number of recorded ticks when there is none. The tick is the key; `time` (s) is only passed
  // to the script (whose errors propagate).
  DeviceSample read(std::int64_t tick, double time) override;
  DeviceLimits limits() const override { return limits_; }
  std::string describe() const override { return "replay of " + source_; }
  Workspace workspace() const override { return reach_box(kWorldReach); }   // world frame, no device
  std::int64_t ticks() const { return static_cast<std::int64_t>(positions_.size()); }
  const Vec3& last_force() const { return last_force_; }   // N, world: last rendered force

 protected:
  void output(const Vec3& force) override { last_force_ = force; }

 private:
  std::vector<Vec3> positions_;   // m, world, one per servo tick
  std::vector<Vec3> gimbals_;     // rad, one per servo tick
  DeviceLimits limits_;
  std::string source_;
  std::unique_ptr<Trajectory> script_;   // evaluated for its side effects only; may be null
  Vec3 last_force_{0.0, 0.0, 0.0};
};

}  // namespace graspsim::hw
