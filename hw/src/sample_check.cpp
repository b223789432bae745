// Device samples checked before the engine sees them (see sample_check.hpp).
#include "graspsim/hw/sample_check.hpp"

#include <cstdio>
#include <utility>

namespace graspsim::hw {
namespace {

std::string vec(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", v.x(), v.y(), v.z());
  return buf;
}

std::string box(const Workspace& w) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "x [%.6g, %.6g], y [%.6g, %.6g], z [%.6g, %.6g] m", w.min.x(), w.max.x(), w.min.y(),
                w.max.y(), w.min.z(), w.max.z());
  return buf;
}

}  // namespace

SampleCheck::SampleCheck(const Device& device, std::string finger)
    : device_(device),
      mapped_(device.device_frame_sample() != nullptr),
      workspace_(device.workspace()),
      finger_(std::move(finger)) {}

void SampleCheck::check(const DeviceSample& world, std::int64_t tick, double time) const {
  const DeviceSample* frame = device_.device_frame_sample();
  const DeviceSample& own = frame ? *frame : world;   // the device's frame
  if (!own.gimbal.allFinite()) refuse(tick, time, "gimbal angles " + vec(own.gimbal) + " rad are not finite");
  if (!own.position.allFinite()) refuse(tick, time, "position " + vec(own.position) + " m is not finite");
  if (!workspace_.contains(own.position)) {
    refuse(tick, time, "position " + vec(own.position) + " m" + (mapped_ ? " (device frame)" : "") +
                           " is outside its workspace, " + box(workspace_));
  }
  // A mapping of a finite position can still overflow (a scale of 1e300).
  if (mapped_ && !world.position.allFinite())
    refuse(tick, time, "position " + vec(world.position) + " m in the world (after the workspace mapping) is not finite");
}

void SampleCheck::refuse(std::int64_t tick, double time, const std::string& what) const {
  char when[80];
  std::snprintf(when, sizeof when, " at tick %lld (t = %.6g s)", static_cast<long long>(tick), time);
  throw BadSample("finger '" + finger_ + "': device " + device_.describe() + when + ": the sample's " + what +
                  "; it was not given to the engine");
}

}  // namespace graspsim::hw
