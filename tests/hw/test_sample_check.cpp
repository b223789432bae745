// The gate between devices and the engine (sample_check.hpp): a sample that is not finite or lies
// outside the device's workspace is refused, naming the finger, the device and the tick.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "graspsim/hw/mapped_device.hpp"
#include "graspsim/hw/replay_device.hpp"
#include "graspsim/hw/sample_check.hpp"
#include "graspsim/hw/sim_phantom.hpp"
#include "graspsim/hw/trajectory.hpp"

using namespace graspsim::hw;
using Catch::Matchers::Contains;

namespace {

// A device that gives whatever sample it is told to, in its own frame.
class Given final : public Device {
 public:
  DeviceSample next;
  DeviceSample read(std::int64_t, double) override { return next; }
  DeviceLimits limits() const override { return {}; }
  std::string describe() const override { return "given"; }

 protected:
  void output(const Vec3&) override {}
};

std::string refusal(const SampleCheck& check, const DeviceSample& s, std::int64_t tick = 7) {
  try {
    check.check(s, tick, tick / 3000.0);
  } catch (const BadSample& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// Finite: NaN or an infinity in any of the three position or gimbal components is refused, with
// the finger, the device, the tick and the time in the message; every finite value inside the
// box passes. The default workspace of a device frame is kDeviceReach = 1 m about its origin.
TEST_CASE("a sample with a NaN or an infinity in its position or gimbal is refused, naming the finger, "
          "device and tick", "[hw][sample_check]") {
  Given device;
  const SampleCheck check(device, "thumb");
  DeviceSample good;
  good.position = {0.1, -0.2, 0.3};
  good.gimbal = {0.0, 1.0, -3.0};
  CHECK(refusal(check, good).empty());
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
    for (int i = 0; i < 3; ++i) {
      DeviceSample s = good;
      s.position[i] = bad;
      const std::string message = refusal(check, s, 1500);
      INFO("position component " << i << " = " << bad);
      CHECK_THAT(message, Contains("finger 'thumb': device given at tick 1500 (t = 0.5 s): the sample's position"));
      CHECK_THAT(message, Contains("is not finite"));
      s = good;
      s.gimbal[i] = bad;
      CHECK_THAT(refusal(check, s), Contains("the sample's gimbal angles"));
    }
  }
}

// The box is closed: a coordinate exactly on a face passes, the next double beyond it is refused;
// swept over every axis and both faces, for the device-frame reach (1 m) and the world reach of a
// replayed trace (1 km).
TEST_CASE("the workspace is a closed box: on a face passes, one ulp beyond is refused, on every axis",
          "[hw][sample_check]") {
  Given device;
  const SampleCheck device_check(device, "index");
  ReplayDevice replay({Vec3::Zero()}, {Vec3::Zero()}, DeviceLimits{}, "rec.h5");
  const SampleCheck world_check(replay, "index");
  for (const auto& [check, reach] : {std::pair{&device_check, kDeviceReach}, std::pair{&world_check, kWorldReach}}) {
    for (int i = 0; i < 3; ++i) {
      for (double side : {-1.0, 1.0}) {
        DeviceSample s;
        s.position[i] = side * reach;
        INFO("reach " << reach << ", axis " << i << ", side " << side);
        CHECK(refusal(*check, s).empty());
        s.position[i] = std::nextafter(side * reach, side * 2.0 * reach);
        CHECK_THAT(refusal(*check, s), Contains("is outside its workspace"));
      }
    }
  }
  DeviceSample far;
  far.position = {1e300, 0.0, 0.0};
  CHECK_THAT(refusal(world_check, far), Contains("x [-1000, 1000], y [-1000, 1000], z [-1000, 1000] m"));
}

// A mapped device is judged in its own frame (its workspace is the device's, wherever the mapping
// puts it in the world): an offset of 5 m moves a sample at 0.9 m to 5.9 m in the world, still
// inside; a device sample at 1.1 m is refused though a scale of 0.1 would put it at 0.11 m. And a
// finite sample that a mapping overflows (1e308 + 1e308 x 0.9 m > DBL_MAX) is refused in the world.
TEST_CASE("a mapped device's samples are checked in its own frame, and in the world for overflow",
          "[hw][sample_check]") {
  const auto mapped = [](const WorkspaceMapping& m) {
    auto inner = std::make_unique<Given>();
    Given* raw = inner.get();
    return std::pair{std::make_unique<MappedDevice>(std::move(inner), m), raw};
  };
  WorkspaceMapping offset;
  offset.offset = {5.0, 0.0, 0.0};
  auto [far, far_inner] = mapped(offset);
  const SampleCheck far_check(*far, "thumb");
  far_inner->next.position = {0.9, 0.0, 0.0};
  DeviceSample world = far->read(0, 0.0);
  CHECK(world.position.x() == 5.9);
  CHECK(refusal(far_check, world).empty());

  WorkspaceMapping small;
  small.scale = 0.1;
  auto [scaled, scaled_inner] = mapped(small);
  const SampleCheck scaled_check(*scaled, "thumb");
  scaled_inner->next.position = {0.0, 1.1, 0.0};
  world = scaled->read(0, 0.0);
  CHECK(world.position.y() == Approx(0.11));
  CHECK_THAT(refusal(scaled_check, world), Contains("(0, 1.1, 0) m (device frame) is outside its workspace"));

  WorkspaceMapping huge;
  huge.scale = 1e308;
  huge.offset = {0.0, 0.0, 1e308};
  auto [overflow, overflow_inner] = mapped(huge);
  const SampleCheck overflow_check(*overflow, "thumb");
  overflow_inner->next.position = {0.0, 0.0, 0.9};
  world = overflow->read(0, 0.0);
  CHECK(std::isinf(world.position.z()));
  CHECK_THAT(refusal(overflow_check, world), Contains("in the world (after the workspace mapping) is not finite"));
}

// A simulated Phantom's workspace is its own box (plus one encoder count): the device stops at
// the box's faces, so a hand that pulls it 1 m away on every axis gives samples the check always
// passes (a workspace one count too small, or one not centred where the device is, would refuse
// them), while the same samples shifted by 2 counts beyond the box are refused.
TEST_CASE("a simulated Phantom's samples stay in its workspace while its hand pulls it against the stops",
          "[hw][sample_check][sim_phantom]") {
  for (const char* model : {"premium-1.5", "touch"}) {
    SimPhantomConfig c;
    c.model = model;
    c.workspace_center = {0.05, -0.02, 0.1};
    const Vec3 start = c.workspace_center;
    auto hand = std::make_unique<WaypointTrajectory>(
        std::vector<Waypoint>{{0.0, start, 0.0}, {0.5, start + Vec3(1.0, 1.0, 1.0), 0.0}, {1.0, start - Vec3(1.0, 1.0, 1.0), 0.0}},
        Interpolation::kLinear);
    SimPhantom device(c, std::move(hand));
    const SampleCheck check(device, "thumb");
    const double count = device_model(model).encoder_resolution;
    Vec3 lowest = Vec3::Constant(1e9), highest = Vec3::Constant(-1e9);
    int refused = 0;
    for (int n = 0; n <= 3000; ++n) {
      const DeviceSample s = device.read(n, n / 3000.0);
      refused += !refusal(check, s, n).empty();
      lowest = lowest.cwiseMin(s.position);
      highest = highest.cwiseMax(s.position);
      device.render(Vec3::Zero());
    }
    INFO(model << ": samples from " << lowest.transpose() << " to " << highest.transpose());
    CHECK(refused == 0);
    // It did reach both stops on every axis (the test is not vacuous).
    CHECK(((highest - device.workspace_max()).cwiseAbs().maxCoeff() <= count));
    CHECK(((lowest - device.workspace_min()).cwiseAbs().maxCoeff() <= count));
    DeviceSample beyond;
    beyond.position = device.workspace_max() + Vec3(2.0 * count, 0.0, 0.0);
    CHECK_THAT(refusal(check, beyond), Contains("outside its workspace"));
  }
}
