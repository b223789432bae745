// MappedDevice: the workspace mapping world = offset + s R p on positions and f_dev = R^T f on
// forces (no scale), checked against rotations written out by hand and by round trips.
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <random>

#include "graspsim/hw/mapped_device.hpp"
#include "graspsim/hw/trajectory.hpp"

using graspsim::hw::DeviceLimits;
using graspsim::hw::DeviceSample;
using graspsim::hw::MappedDevice;
using graspsim::hw::Vec3;
using graspsim::hw::WorkspaceMapping;

namespace {

// A device that reports a set position and keeps the last force it was sent (device frame).
class FakeDevice final : public graspsim::hw::Device {
 public:
  Vec3 position{0.0, 0.0, 0.0};
  Vec3 last_force{1.0, 1.0, 1.0};
  double max_force = 5.0;
  DeviceSample read(std::int64_t, double) override {
    DeviceSample s;
    s.position = position;
    s.gimbal = {0.1, 0.2, 0.3};
    s.buttons = 5;
    return s;
  }
  DeviceLimits limits() const override { return DeviceLimits{max_force}; }
  std::string describe() const override { return "fake"; }

 protected:
  void output(const Vec3& f) override { last_force = f; }
};

// A device with its own clock, sample numbers and recorded pacing (what a UDP or replayed device
// says of itself through the Device interface).
class ClockedDevice final : public graspsim::hw::Device {
 public:
  DeviceSample read(std::int64_t tick, double) override {
    tick_ = tick;
    DeviceSample s;
    s.position = {0.01 * static_cast<double>(tick), 0.0, 0.0};
    return s;
  }
  DeviceLimits limits() const override { return DeviceLimits{5.0}; }
  std::string describe() const override { return "clocked"; }
  bool has_sample_clock() const override { return true; }
  double sample_time() const override { return 0.001 * static_cast<double>(tick_); }
  std::int64_t sample_sequence() const override { return 100 + tick_; }
  std::int64_t new_samples() const override { return 2; }
  bool has_recorded_pacing() const override { return true; }
  bool recorded_overrun() const override { return tick_ % 2 == 1; }

 protected:
  void output(const Vec3&) override {}

 private:
  std::int64_t tick_ = -1;
};

constexpr double kPi = 3.14159265358979323846;

}  // namespace

TEST_CASE("Workspace mapping: a yaw of 90 degrees, scale 2 and an offset, by hand", "[hw][mapping]") {
  // Law: world = offset + s R p. With R = Rz(90 deg): device x -> world y, device y -> world -x.
  // p = (0.1, 0.05, 0.02), s = 2, offset (1, 2, 3): world = (1 - 0.1, 2 + 0.2, 3 + 0.04).
  // Forces: f_dev = R^T f_world: world y -> device x, world x -> device -y; no factor 1/s.
  // Tolerance 1e-15 m / N: cos(pi/2) = 6.1e-17 in double, a few ulp at these magnitudes.
  auto fake = std::make_unique<FakeDevice>();
  FakeDevice* raw = fake.get();
  raw->position = {0.1, 0.05, 0.02};
  WorkspaceMapping m;
  m.scale = 2.0;
  m.offset = {1.0, 2.0, 3.0};
  m.rotation = {0.0, 0.0, kPi / 2.0};
  MappedDevice d(std::move(fake), m);
  const DeviceSample s = d.read(0, 0.0);
  CHECK(std::abs(s.position.x() - 0.9) < 1e-15);
  CHECK(std::abs(s.position.y() - 2.2) < 1e-15);
  CHECK(std::abs(s.position.z() - 3.04) < 1e-15);
  CHECK(s.gimbal == Vec3(0.1, 0.2, 0.3));   // gimbal angles pass through
  CHECK(s.buttons == 5u);
  CHECK(d.last_device_sample().position == raw->position);   // kept in the device frame
  d.render(Vec3(1.0, 2.0, 0.5));
  CHECK(std::abs(raw->last_force.x() - 2.0) < 1e-15);
  CHECK(std::abs(raw->last_force.y() + 1.0) < 1e-15);
  CHECK(std::abs(raw->last_force.z() - 0.5) < 1e-15);
  CHECK(d.last_device_force() == raw->last_force);
  d.release();
  CHECK(raw->last_force == Vec3::Zero());   // release reaches the wrapped device
}

TEST_CASE("Workspace mapping: round trips of positions and forces over random mappings", "[hw][mapping]") {
  // Laws: to_device(to_world(p)) = p; R (R^T f) = f; |R^T f| = |f| (a rotation keeps the norm,
  // so the clamp is the same in either frame). Swept over 200 random mappings, scale 0.1 to 10.
  // Tolerance: 1e-14 relative to the magnitudes involved (a handful of roundings of products
  // of O(1) rotation entries; the offset is up to 1 m and p up to 0.2 m).
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-kPi, kPi), unit(-1.0, 1.0), log_scale(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    WorkspaceMapping m;
    m.scale = std::pow(10.0, log_scale(rng));
    m.offset = {unit(rng), unit(rng), unit(rng)};
    m.rotation = {angle(rng), angle(rng) / 2.0, angle(rng)};
    const Vec3 p = 0.2 * Vec3(unit(rng), unit(rng), unit(rng));
    const Vec3 back = m.to_device(m.to_world(p));
    CHECK((back - p).norm() < 1e-14 * (1.0 + 1.0 / m.scale));
    const Eigen::Matrix3d r = m.rotation_matrix();
    CHECK((r * r.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-14);
    const Vec3 f = 10.0 * Vec3(unit(rng), unit(rng), unit(rng));
    CHECK((r * m.force_to_device(f) - f).norm() < 1e-14 * 10.0);
    CHECK(std::abs(m.force_to_device(f).norm() - f.norm()) < 1e-14 * 10.0);
  }
}

TEST_CASE("Workspace mapping: the rotation is Rz(yaw) Ry(pitch) Rx(roll)", "[hw][mapping]") {
  // Each axis alone, by hand: roll 90 deg takes y to z, pitch 90 deg takes z to x, yaw 90 deg
  // takes x to y; the composition applies roll first: roll then yaw takes y -> z -> z, and
  // z -> -y -> x (Rz(90) takes y to -x, so -y to x). Tolerance 1e-15: cos(pi/2) = 6e-17.
  const auto map = [](double roll, double pitch, double yaw, const Vec3& p) {
    WorkspaceMapping m;
    m.rotation = {roll, pitch, yaw};
    return m.to_world(p);
  };
  const double q = kPi / 2.0;
  CHECK((map(q, 0, 0, Vec3::UnitY()) - Vec3::UnitZ()).norm() < 1e-15);
  CHECK((map(0, q, 0, Vec3::UnitZ()) - Vec3::UnitX()).norm() < 1e-15);
  CHECK((map(0, 0, q, Vec3::UnitX()) - Vec3::UnitY()).norm() < 1e-15);
  CHECK((map(q, 0, q, Vec3::UnitY()) - Vec3::UnitZ()).norm() < 1e-15);
  CHECK((map(q, 0, q, Vec3::UnitZ()) - Vec3::UnitX()).norm() < 1e-15);
}

TEST_CASE("Workspace mapping: forces are clamped to the device's limit in the device frame", "[hw][mapping]") {
  // The clamp holds after the mapping: any world force (huge, NaN) reaches the device at most at
  // its limit (5 N), NaN as zero.
  auto fake = std::make_unique<FakeDevice>();
  FakeDevice* raw = fake.get();
  WorkspaceMapping m;
  m.scale = 3.0;
  m.rotation = {0.3, -0.2, 1.1};
  MappedDevice d(std::move(fake), m);
  d.render(Vec3(1e300, -1e300, 3.0));
  CHECK(raw->last_force.norm() <= 5.0);
  CHECK(raw->last_force.norm() > 4.99);
  d.render(Vec3(std::nan(""), 0.0, 0.0));
  CHECK(raw->last_force == Vec3::Zero());
}

TEST_CASE("Workspace mapping: a world trajectory seen in the device frame maps back onto itself", "[hw][mapping]") {
  // to_world(trajectory_in_device_frame(w)(t)) = w(t): a scripted hand holding a mapped device
  // puts it where the scenario's script says. Tolerance 1e-15 m (O(0.1 m) values, a few ulp).
  WorkspaceMapping m;
  m.scale = 0.5;
  m.offset = {0.1, -0.2, 0.3};
  m.rotation = {0.0, 0.4, -0.7};
  std::vector<graspsim::hw::Waypoint> w = {{0.0, {0.0, 0.0, 0.05}, 0.0}, {1.0, {0.1, 0.02, 0.1}, 0.3}};
  auto world = std::make_unique<graspsim::hw::WaypointTrajectory>(w, graspsim::hw::Interpolation::kLinear);
  graspsim::hw::WaypointTrajectory reference(w, graspsim::hw::Interpolation::kLinear);
  auto device = graspsim::hw::trajectory_in_device_frame(std::move(world), m);
  for (double t : {0.0, 0.25, 0.5, 1.0}) {
    const auto s = device->sample(t);
    CHECK((m.to_world(s.position) - reference.position(t)).norm() < 1e-15);
    CHECK(s.gimbal.y() == reference.sample(t).gimbal.y());
  }
}

// A device describes itself through the Device interface (hw/README.md): a plain device has no
// clock, no sample numbers (-1), no recorded pacing, and the world as its frame; a mapped one
// gives its device-frame sample, force and mapping, and passes on what the wrapped device says
// of its clock, numbers and pacing unchanged (the /devices row of a mapped UDP device keeps the
// server's clock). Exact: nothing is computed on the way, only passed on.
TEST_CASE("A device describes itself, and a mapped device passes on what the wrapped one says",
          "[hw][mapping][describe]") {
  FakeDevice plain;
  CHECK_FALSE(plain.has_sample_clock());
  CHECK(plain.sample_sequence() == -1);
  CHECK(plain.new_samples() == -1);
  CHECK_FALSE(plain.has_recorded_pacing());
  CHECK(plain.device_frame_sample() == nullptr);
  CHECK(plain.device_frame_force() == nullptr);
  CHECK(plain.mapping_text() == "identity (device frame = world)");

  WorkspaceMapping m;
  m.scale = 2.0;
  m.offset = {0.5, 0.0, 0.0};
  MappedDevice d(std::make_unique<ClockedDevice>(), m);
  for (std::int64_t tick : {0, 1, 7}) {
    const DeviceSample world = d.read(tick, 0.0);
    REQUIRE(d.device_frame_sample() != nullptr);
    CHECK(d.device_frame_sample()->position.x() == 0.01 * static_cast<double>(tick));   // before the mapping
    CHECK(world.position.x() == 0.5 + 2.0 * (0.01 * static_cast<double>(tick)));
    CHECK(d.has_sample_clock());
    CHECK(d.sample_time() == 0.001 * static_cast<double>(tick));
    CHECK(d.sample_sequence() == 100 + tick);
    CHECK(d.new_samples() == 2);
    CHECK(d.has_recorded_pacing());
    CHECK(d.recorded_overrun() == (tick % 2 == 1));
  }
  d.render(Vec3(1.0, 0.0, 0.0));
  REQUIRE(d.device_frame_force() != nullptr);
  CHECK(*d.device_frame_force() == Vec3(1.0, 0.0, 0.0));   // no rotation: the same force
  CHECK(d.mapping_text() == "scale 2; offset 0.5 0 0 m; rotation 0 0 0 rad");
}
