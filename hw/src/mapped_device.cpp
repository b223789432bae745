// Workspace mapping of a device: positions to the world, forces back to the device.
#include "graspsim/hw/mapped_device.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace graspsim::hw {

Eigen::Matrix3d WorkspaceMapping::rotation_matrix() const {
  return (Eigen::AngleAxisd(rotation.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rotation.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rotation.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

Vec3 WorkspaceMapping::to_world(const Vec3& p) const { return offset + scale * (rotation_matrix() * p); }

Vec3 WorkspaceMapping::to_device(const Vec3& x) const {
  return rotation_matrix().transpose() * (x - offset) / scale;
}

Vec3 WorkspaceMapping::force_to_device(const Vec3& f) const { return rotation_matrix().transpose() * f; }

MappedDevice::MappedDevice(std::unique_ptr<Device> device, const WorkspaceMapping& mapping)
    : device_(std::move(device)), mapping_(mapping), rotation_(mapping.rotation_matrix()) {
  if (!device_) throw std::invalid_argument("mapped device: no device");
  if (!(mapping_.scale > 0.0) || !std::isfinite(mapping_.scale) || !mapping_.offset.allFinite() ||
      !mapping_.rotation.allFinite())
    throw std::invalid_argument("mapped device: the scale must be > 0 and finite, offset and rotation finite");
}

DeviceSample MappedDevice::read(std::int64_t tick, double time) {
  last_sample_ = device_->read(tick, time);
  DeviceSample world = last_sample_;
  world.position = mapping_.offset + mapping_.scale * (rotation_ * last_sample_.position);
  return world;
}

void MappedDevice::output(const Vec3& force) {
  // Already clamped by Device::render in the world frame; the inner render clamps again in the
  // device frame (the same norm: R is a rotation), so no path reaches the hardware unclamped.
  last_force_ = device_->render(rotation_.transpose() * force);
}

std::string MappedDevice::describe() const {
  std::ostringstream s;
  s << device_->describe() << " mapped (scale " << mapping_.scale << ", offset " << mapping_.offset.x() << ","
    << mapping_.offset.y() << "," << mapping_.offset.z() << " m, rotation " << mapping_.rotation.x() << ","
    << mapping_.rotation.y() << "," << mapping_.rotation.z() << " rad)";
  return s.str();
}

// Every digit (%.17g), so a replay parses back the very mapping the run used.
std::string MappedDevice::mapping_text() const {
  const WorkspaceMapping& m = mapping_;
  char buf[256];
  std::snprintf(buf, sizeof buf, "scale %.17g; offset %.17g %.17g %.17g m; rotation %.17g %.17g %.17g rad", m.scale,
                m.offset.x(), m.offset.y(), m.offset.z(), m.rotation.x(), m.rotation.y(), m.rotation.z());
  return buf;
}

namespace {
class DeviceFrameTrajectory final : public Trajectory {
 public:
  DeviceFrameTrajectory(std::unique_ptr<Trajectory> world, const WorkspaceMapping& mapping)
      : world_(std::move(world)), mapping_(mapping) {}
  TrajectorySample sample(double t) override {
    TrajectorySample s = world_->sample(t);
    s.position = mapping_.to_device(s.position);
    return s;
  }

 private:
  std::unique_ptr<Trajectory> world_;
  WorkspaceMapping mapping_;
};
}  // namespace

std::unique_ptr<Trajectory> trajectory_in_device_frame(std::unique_ptr<Trajectory> world,
                                                       const WorkspaceMapping& mapping) {
  if (!world) throw std::invalid_argument("trajectory_in_device_frame: no trajectory");
  return std::make_unique<DeviceFrameTrajectory>(std::move(world), mapping);
}

}  // namespace graspsim::hw
