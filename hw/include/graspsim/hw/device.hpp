// The device interface: what a finger's source of motion must do. A scripted finger, a replayed
// trace, a simulated or a real Phantom all implement it, so any of them can drive any finger
// without the engine knowing which (CHAI3D's shape: read a sample, render a force).
#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "graspsim/hw/force_safety.hpp"

namespace graspsim::hw {

// One reading of a device, already mapped into the world frame.
struct DeviceSample {
  Vec3 position{0.0, 0.0, 0.0};   // m, world: haptic interface point (HIP)
  Vec3 gimbal{0.0, 0.0, 0.0};     // rad: stylus gimbal angles (roll, pitch, yaw); 0 if none
  std::uint32_t buttons = 0;      // bit i set while button i is pressed
};

// A box in a device's own frame (the frame of its samples, before a workspace mapping): where
// its samples may be. A sample outside it, or not finite, never reaches the engine (SampleCheck).
struct Workspace {
  Vec3 min{0.0, 0.0, 0.0};   // m: lower corner
  Vec3 max{0.0, 0.0, 0.0};   // m: upper corner
  bool contains(const Vec3& p) const;   // false for a NaN
};

// Workspaces for devices that do not know theirs exactly (hw/README.md, "Sample checks"):
// - kDeviceReach: a device's own frame, |x|, |y|, |z| <= 1 m about its origin. The largest
//   desktop haptic device spans 0.38 m (the Premium 1.5), and a server's origin may sit off its
//   workspace's centre; no hand on such a device reaches 1 m, while 1e300, or an encoder read as
//   garbage, is far outside. A scaled workspace mapping then multiplies the reach in the world.
// - kWorldReach: world-frame samples with no device behind them (a script, a replayed trace), up
//   to 1 km from the origin: further than any scene, and small enough that squares of positions
//   (distances in contact tests) stay far from overflow with 13 digits left below a micrometre.
inline constexpr double kDeviceReach = 1.0;     // m
inline constexpr double kWorldReach = 1000.0;   // m
Workspace reach_box(double half_side);          // [-half_side, half_side]^3, m

class Device {
 public:
  virtual ~Device() = default;
  // Reads the sample for servo tick `tick` at simulated time `time` (s). Must not block.
  virtual DeviceSample read(std::int64_t tick, double time) = 0;
  // Renders `force` (N, world) after clamping it to limits() (force_safety.hpp); returns what
  // was rendered.
  Vec3 render(const Vec3& force) {
    const Vec3 safe = clamp_force(force, limits());
    output(safe);
    return safe;
  }
  // Renders zero force: at the end of a run, on error, when the loop stalls. Then on_release().
  void release() {
    output(Vec3::Zero());
    on_release();
  }
  virtual DeviceLimits limits() const = 0;
  virtual std::string describe() const = 0;   // for messages and the trace, e.g. "scripted"
  // Where this device's samples may be, in its own frame: reach_box(kDeviceReach) unless the
  // device knows better (a simulated Phantom: its box) or has no device frame (kWorldReach).
  virtual Workspace workspace() const { return reach_box(kDeviceReach); }

  // What a device says of itself for its /devices/<finger> table (recordings/README.md), so the
  // run loop asks the interface instead of probing types. The defaults describe a device with no
  // clock of its own, no sample numbers, no recorded pacing, and the world as its frame.
  // Its own clock: whether it has one, and when the last read sample was taken on it (s).
  virtual bool has_sample_clock() const { return false; }
  virtual double sample_time() const { return 0.0; }
  // 1: the device's number of the sample the last read() returned (-1: none, or before any);
  // UDP: the server's sequence number; OpenHaptics: the HD servo frame it was read in.
  virtual std::int64_t sample_sequence() const { return -1; }
  // 1: new samples between the previous read() and the last one (0: held; -1: not known).
  virtual std::int64_t new_samples() const { return -1; }
  // A replayed device: whether the recorded run overran the tick of the last sample read
  // (has_recorded_pacing false: the run's own pacing decides).
  virtual bool has_recorded_pacing() const { return false; }
  virtual bool recorded_overrun() const { return false; }
  // Its own frame when that is not the world (a workspace mapping, MappedDevice): the last sample
  // as the device gave it and the last force sent to it, both in that frame (nullptr: the frame is
  // the world, so they are what read() returned and render() rendered), and the mapping as text.
  virtual const DeviceSample* device_frame_sample() const { return nullptr; }
  virtual const Vec3* device_frame_force() const { return nullptr; }
  virtual std::string mapping_text() const { return "identity (device frame = world)"; }

 protected:
  // Sends an already clamped force to the hardware (or stores it).
  virtual void output(const Vec3& force) = 0;
  // Called by release() after the zero force is sent: a backend re-arms its force ramp here
  // (ForceSafety::release), so the next force after a release rises from zero again.
  virtual void on_release() {}
};

}  // namespace graspsim::hw
