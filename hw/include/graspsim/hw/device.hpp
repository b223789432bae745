// The device interface: what a finger's source of motion must do. A scripted finger, a replayed
// trace, a simulated or a real Phantom all implement it, so any of them can drive any finger
// without the engine knowing which (CHAI3D's shape: read a sample, render a force).
#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>

namespace graspsim::hw {

using Vec3 = Eigen::Vector3d;

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

struct DeviceLimits {
  double max_force = 10.0;   // N: largest force magnitude the device may render
};

// Force safety, in one place: the largest force a device may be asked for is the limit, in the
// direction asked; NaN or infinite components render zero (a non-finite request is a fault, and
// the safe output for a fault is no force).
Vec3 clamp_force(const Vec3& force, const DeviceLimits& limits);

class Device {
 public:
  virtual ~Device() = default;
  // Reads the sample for servo tick `tick` at simulated time `time` (s). Must not block.
  virtual DeviceSample read(std::int64_t tick, double time) = 0;
  // Renders `force` (N, world) after clamping it to limits(); returns what was rendered.
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

 protected:
  // Sends an already clamped force to the hardware (or stores it).
  virtual void output(const Vec3& force) = 0;
  // Called by release() after the zero force is sent: a backend re-arms its force ramp here
  // (ForceSafety::release), so the next force after a release rises from zero again.
  virtual void on_release() {}
};

}  // namespace graspsim::hw
