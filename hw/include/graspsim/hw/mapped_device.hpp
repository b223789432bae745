// Workspace mapping: a device works in its own frame and units (after its backend converted to
// SI); the scenario places that workspace in the world. world = offset + scale R p, with R from
// roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll), the gimbal's own convention). Forces go the
// other way: f_device = R^T f_world, NOT divided by the scale (see MappedDevice).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Geometry>

#include "graspsim/hw/device.hpp"
#include "graspsim/hw/trajectory.hpp"

namespace graspsim::hw {

struct WorkspaceMapping {
  double scale = 1.0;               // 1 (m world per m device): motion scaling, > 0
  Vec3 offset{0.0, 0.0, 0.0};       // m, world: where the device frame's origin sits
  Vec3 rotation{0.0, 0.0, 0.0};     // rad: roll, pitch, yaw of the device frame in the world
  bool is_identity() const { return scale == 1.0 && offset.isZero(0.0) && rotation.isZero(0.0); }
  Eigen::Matrix3d rotation_matrix() const;                 // 1: device to world
  Vec3 to_world(const Vec3& device_position) const;        // m: offset + scale R p
  Vec3 to_device(const Vec3& world_position) const;        // m: R^T (x - offset) / scale
  Vec3 force_to_device(const Vec3& world_force) const;     // N: R^T f (no scale)
};

// A device seen through a workspace mapping. Positions: device -> world (offset + s R p).
// Forces: world -> device by R^T only. Why a scale does not scale forces: the scale is a motion
// gain for the hand (a 2x scale lets a small workspace cover a large scene); the force the
// engine computes is the force the user should feel, and dividing it by s would make contact
// feel softer (k / s) on a scaled device and change the clamp the user is protected by. The
// limits are the wrapped device's (a rotation keeps the norm, so clamping before or after the
// rotation gives the same magnitude). Gimbal angles pass through unchanged: they are the
// stylus' angles relative to the device, which the engine uses as relative twist (pitch).
class MappedDevice final : public Device {
 public:
  // Throws std::invalid_argument for a null device or a scale that is not > 0 and finite.
  MappedDevice(std::unique_ptr<Device> device, const WorkspaceMapping& mapping);
  DeviceSample read(std::int64_t tick, double time) override;
  DeviceLimits limits() const override { return device_->limits(); }
  std::string describe() const override;
  Workspace workspace() const override { return device_->workspace(); }   // the device frame's
  const DeviceSample& last_device_sample() const { return last_sample_; }   // device frame
  const Vec3& last_device_force() const { return last_force_; }             // N, device frame
  // The device frame for its /devices table; clock, numbering and pacing are the wrapped device's.
  const DeviceSample* device_frame_sample() const override { return &last_sample_; }
  const Vec3* device_frame_force() const override { return &last_force_; }
  std::string mapping_text() const override;   // "scale S; offset X Y Z m; rotation R P Y rad", %.17g
  bool has_sample_clock() const override { return device_->has_sample_clock(); }
  double sample_time() const override { return device_->sample_time(); }
  std::int64_t sample_sequence() const override { return device_->sample_sequence(); }
  std::int64_t new_samples() const override { return device_->new_samples(); }
  bool has_recorded_pacing() const override { return device_->has_recorded_pacing(); }
  bool recorded_overrun() const override { return device_->recorded_overrun(); }
  Device& inner() { return *device_; }
  const Device& inner() const { return *device_; }
  const WorkspaceMapping& mapping() const { return mapping_; }

 protected:
  void output(const Vec3& force) override;
  void on_release() override { device_->release(); }   // the wrapped device re-arms its ramp too

 private:
  std::unique_ptr<Device> device_;
  WorkspaceMapping mapping_;
  Eigen::Matrix3d rotation_;             // 1: device to world, from mapping_.rotation
  DeviceSample last_sample_;             // device frame, as the device gave it
  Vec3 last_force_{0.0, 0.0, 0.0};       // N, device frame: last force handed to the device
};

// A world-frame trajectory seen in a device frame: x_device = R^T (x_world - offset) / scale.
// For a device whose hand is scripted in the scenario's (world) terms, e.g. a simulated Phantom
// held by a scripted hand, so that the mapped device ends up where the script says.
std::unique_ptr<Trajectory> trajectory_in_device_frame(std::unique_ptr<Trajectory> world,
                                                       const WorkspaceMapping& mapping);

}  // namespace graspsim::hw
