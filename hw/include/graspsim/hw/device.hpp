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
  // Renders zero force: at the end of a run, on error, when the loop stalls.
  void release() {
    output(Vec3::Zero());
    on_release();
  }
  virtual DeviceLimits limits() const = 0;
  virtual std::string describe() const = 0;   // for messages and the trace, e.g. "scripted"

 protected:
  // Sends an already clamped force to the hardware (or stores it).
  virtual void output(const Vec3& force) = 0;
  // Called by release() after the zero force was sent: a device that ramps its force in
  // (ForceSafety) restarts the ramp here.
  virtual void on_release() {}
};

}  // namespace graspsim::hw
