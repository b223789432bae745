// ReplayDevice: recorded samples come back bit for bit at their tick, a tick outside the
// recording is an error naming it, and forces are clamped like any device's.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>

#include "graspsim/hw/replay_device.hpp"

using graspsim::hw::DeviceLimits;
using graspsim::hw::ReplayDevice;
using graspsim::hw::Vec3;

TEST_CASE("ReplayDevice returns row n at tick n, bit for bit", "[hw][replay]") {
  // Values with every mantissa bit in use, a -0 and a denormal: nothing may round or normalise.
  const std::vector<Vec3> hip = {{0.1, -0.0, 1.0 / 3.0}, {std::nextafter(0.2, 1.0), 4.9e-324, -7.25}};
  const std::vector<Vec3> gimbal = {{0.0, 0.5, 0.0}, {0.0, std::acos(-1.0) / 2.0, -0.0}};
  ReplayDevice d(hip, gimbal, DeviceLimits{5.0}, "t.h5");
  CHECK(d.ticks() == 2);
  for (std::int64_t n = 0; n < 2; ++n) {
    // The time argument is ignored: the tick is the key.
    const auto s = d.read(n, 123.0);
    for (int i = 0; i < 3; ++i) {
      CHECK(std::signbit(s.position[i]) == std::signbit(hip[n][i]));
      CHECK(std::memcmp(&s.position[i], &hip[n][i], sizeof(double)) == 0);
      CHECK(std::memcmp(&s.gimbal[i], &gimbal[n][i], sizeof(double)) == 0);
    }
    CHECK(s.buttons == 0);
  }
  CHECK(d.describe() == "replay of t.h5");
}

TEST_CASE("ReplayDevice: a tick outside the recording is an error naming it", "[hw][replay]") {
  ReplayDevice d({Vec3::Zero()}, {Vec3::Zero()}, DeviceLimits{}, "t.h5");
  CHECK_THROWS_WITH(d.read(1, 0.0), Catch::Contains("no recorded sample for servo tick 1") &&
                                        Catch::Contains("ticks 0 to 0"));
  CHECK_THROWS_AS(d.read(-1, 0.0), std::out_of_range);
  CHECK_THROWS_AS(ReplayDevice({Vec3::Zero()}, {}, DeviceLimits{}, "t.h5"), std::invalid_argument);
}

TEST_CASE("ReplayDevice renders through the same clamp as every device", "[hw][replay]") {
  // |(3, 4, 0)| = 5 N: at a 2.5 N limit the rendered force is half of it (to the clamp's 4 ulp).
  ReplayDevice d({Vec3::Zero()}, {Vec3::Zero()}, DeviceLimits{2.5}, "t.h5");
  const Vec3 r = d.render(Vec3(3.0, 4.0, 0.0));
  CHECK(r.norm() <= 2.5);
  CHECK(r.norm() == Approx(2.5).epsilon(1e-15));
  CHECK(d.last_force() == r);
  d.release();
  CHECK(d.last_force() == Vec3::Zero());
}

namespace {
// A script that remembers the times it was asked for and answers something else entirely.
struct Recorder final : graspsim::hw::Trajectory {
  std::vector<double>* times;
  explicit Recorder(std::vector<double>* t) : times(t) {}
  graspsim::hw::TrajectorySample sample(double t) override {
    times->push_back(t);
    return {Vec3(9.0, 9.0, 9.0), Vec3(1.0, 1.0, 1.0)};
  }
};
}  // namespace

TEST_CASE("ReplayDevice still runs the finger's script at every read, and ignores its motion",
          "[hw][replay]") {
  std::vector<double> times;
  ReplayDevice d({Vec3(0.1, 0.2, 0.3), Vec3(0.4, 0.5, 0.6)}, {Vec3::Zero(), Vec3::Zero()}, DeviceLimits{}, "t.h5",
                 std::make_unique<Recorder>(&times));
  CHECK(d.read(0, 0.0).position == Vec3(0.1, 0.2, 0.3));
  CHECK(d.read(1, 1.0 / 3000.0).position == Vec3(0.4, 0.5, 0.6));
  CHECK(d.read(1, 1.0 / 3000.0).gimbal == Vec3::Zero());
  CHECK(times == std::vector<double>{0.0, 1.0 / 3000.0, 1.0 / 3000.0});
}
