// The OpenHaptics backend against the HD API test double (tests/hw/openhaptics_double): units
// and axes in, clamped forces out, start-up limits, the one shared servo callback, and the
// error paths. The double runs the scheduler's callbacks on this thread, one frame per
// run_frames(1), so nothing here depends on timing.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "graspsim/hw/openhaptics_device.hpp"
#include "hd_double.hpp"

using graspsim::hw::Device;
using graspsim::hw::kOpenHapticsStallFrames;
using graspsim::hw::make_openhaptics_device;
using graspsim::hw::OpenHapticsDevice;
using graspsim::hw::Vec3;

namespace {

// The device frame (x right, y away from the user, z up) from OpenHaptics axes (x right, y up,
// z toward the user), with mm -> m: the mapping the backend documents, written out here once.
Vec3 expected_position(const std::array<double, 3>& mm) {
  return Vec3(mm[0] / 1000.0, -(mm[2] / 1000.0), mm[1] / 1000.0);
}
// A device-frame force in OpenHaptics axes: the inverse (transpose) of the same rotation.
std::array<double, 3> expected_hd_force(const Vec3& f) { return {f.x(), f.z(), -f.y()}; }

Vec3 as_vec(const std::array<double, 3>& a) { return Vec3(a[0], a[1], a[2]); }

// The clamp and the servo's stall alone: no ramp, and a device whose continuous force is its peak
// (no thermal derating), so the force committed is the clamped request bit for bit. The force
// safety law itself is tested in test_openhaptics_safety.cpp.
const graspsim::hw::OpenHapticsOptions kNoRamp{/*rise_time=*/0.0};
std::unique_ptr<Device> open_clamp_only(hd_double::FakeDevice& fake, const std::string& name) {
  fake.max_continuous_force = fake.max_force;
  return make_openhaptics_device(name, kNoRamp);
}

// Every test starts from an empty double and must leave no API misuse behind.
struct Fresh {
  Fresh() { hd_double::reset(); }
  ~Fresh() {
    for (const auto& v : hd_double::violations()) FAIL_CHECK("HD API misuse: " << v);
  }
};

}  // namespace

TEST_CASE("OpenHaptics: positions in mm become m in the device frame (x right, y away, z up)",
          "[hw][openhaptics]") {
  Fresh fresh;
  auto& fake = hd_double::add_device("Default PHANToM");
  fake.position_mm = {12.5, -40.0, 73.0};
  auto dev = make_openhaptics_device("Default PHANToM");
  // The factory waits for one servo frame, so the very first read is the device's real position,
  // not a placeholder zero. The conversion is one IEEE division by 1000 and a sign: exact match.
  CHECK(dev->read(0, 0.0).position == expected_position(fake.position_mm));

  // A sweep of positions over a Premium 1.5's workspace (about +-200 mm), values with full
  // mantissas included; each sample arrives after one servo frame.
  const std::vector<std::array<double, 3>> sweep = {
      {0.0, 0.0, 0.0}, {-190.0, 0.1, 3.0 / 7.0}, {1.0 / 3.0, 200.0, -150.25}, {-0.0, -1e-3, 88.8}};
  for (const auto& p : sweep) {
    fake.position_mm = p;
    hd_double::run_frames(1);
    const Vec3 got = dev->read(1, 0.001).position;
    INFO("HD position (mm) " << p[0] << ", " << p[1] << ", " << p[2]);
    CHECK(got == expected_position(p));
  }

  // The mapping is a proper rotation (right-handed frame, det +1): its columns are the images
  // of the HD unit axes, measured through the backend with 1000 mm moves.
  Eigen::Matrix3d R;
  for (int axis = 0; axis < 3; ++axis) {
    fake.position_mm = {0.0, 0.0, 0.0};
    fake.position_mm[axis] = 1000.0;
    hd_double::run_frames(1);
    R.col(axis) = dev->read(2, 0.002).position;
  }
  CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() == 0.0);
  CHECK(R.determinant() == 1.0);
  // OpenHaptics up (+y) is the device frame's up (+z); toward the user (+z) is -y.
  CHECK(R.col(1) == Vec3(0.0, 0.0, 1.0));
  CHECK(R.col(2) == Vec3(0.0, -1.0, 0.0));
}

TEST_CASE("OpenHaptics: gimbal angles (rad) and button bits pass through unchanged",
          "[hw][openhaptics]") {
  Fresh fresh;
  auto& fake = hd_double::add_device("Right");
  auto dev = make_openhaptics_device("Right");
  for (int buttons : {0, HD_DEVICE_BUTTON_1, HD_DEVICE_BUTTON_2,
                      HD_DEVICE_BUTTON_1 | HD_DEVICE_BUTTON_2}) {
    fake.gimbal = {0.25 * buttons - 0.3, std::acos(-1.0) / 3.0, -1.5};
    fake.buttons = buttons;
    hd_double::run_frames(1);
    const auto s = dev->read(0, 0.0);
    CHECK(s.gimbal == as_vec(fake.gimbal));
    CHECK(s.buttons == static_cast<std::uint32_t>(buttons));
  }
}

TEST_CASE("OpenHaptics: forces go out in N on HD axes, clamped to the nominal max force",
          "[hw][openhaptics]") {
  // The law: the force committed to the motors is clamp(f) rotated into HD axes, where clamp
  // keeps f when |f| <= F_max and scales it to F_max along f otherwise. device.cpp shrinks the
  // result by 4 eps (8.9e-16) so that |F| <= F_max however the norm is summed; with a few ulp of
  // rounding in the norm and the rotation, |F| >= F_max (1 - 1e-14) and the direction's cosine is
  // 1 to 1e-14 (about ten times what the arithmetic can lose, far below any real error). Swept over the peak forces of
  // the Omni/Touch (3.3 N), Premium 1.5 (8.5 N) and 1.5 High Force (37.5 N).
  for (double f_max : {3.3, 8.5, 37.5}) {
    Fresh fresh;
    auto& fake = hd_double::add_device("P");
    fake.max_force = f_max;
    auto dev = open_clamp_only(fake, "P");
    REQUIRE(dev->limits().max_force == f_max);
    INFO("F_max = " << f_max << " N");

    // Below the limit: passed through exactly, only rotated.
    const Vec3 small(0.3, -0.2, 0.1 * f_max);
    CHECK(dev->render(small) == small);
    // Nothing reaches the motors until the servo frame runs.
    CHECK(as_vec(fake.force) == Vec3::Zero());
    hd_double::run_frames(1);
    CHECK(as_vec(fake.force) == as_vec(expected_hd_force(small)));

    // Above the limit, in several directions, one with components near DBL_MAX / 1e8.
    for (const Vec3& big : {Vec3(100.0, 0.0, 0.0), Vec3(0.0, -3.0 * f_max, 0.0),
                            Vec3(Vec3(-7.0, 11.0, 13.0) * f_max), Vec3(1e300, 1e300, -1e300)}) {
      const Vec3 rendered = dev->render(big);
      hd_double::run_frames(1);
      const Vec3 out = as_vec(fake.force);
      INFO("asked " << big.transpose() << " N");
      CHECK(out == as_vec(expected_hd_force(rendered)));
      CHECK(out.norm() <= f_max);
      CHECK(out.norm() >= f_max * (1.0 - 1e-14));
      // Direction: scale by the largest component first, so |big|^2 cannot overflow.
      const Vec3 asked_hd = as_vec(expected_hd_force(big / big.cwiseAbs().maxCoeff())).normalized();
      CHECK(out.normalized().dot(asked_hd) >= 1.0 - 1e-14);
    }

    // A non-finite request is a fault: zero goes out.
    dev->render(Vec3(std::numeric_limits<double>::quiet_NaN(), 1.0, 1.0));
    hd_double::run_frames(1);
    CHECK(as_vec(fake.force) == Vec3::Zero());

    // release() renders zero.
    dev->render(small);
    hd_double::run_frames(1);
    REQUIRE(as_vec(fake.force) != Vec3::Zero());
    dev->release();
    hd_double::run_frames(1);
    CHECK(as_vec(fake.force) == Vec3::Zero());
  }
}

TEST_CASE("OpenHaptics: start-up reads the nominal limits and enables force output",
          "[hw][openhaptics]") {
  Fresh fresh;
  auto& fake = hd_double::add_device("Premium");
  fake.max_force = 8.5;
  fake.max_continuous_force = 1.4;
  fake.max_stiffness = 3.5;   // N/mm, as HD reports it
  auto dev = make_openhaptics_device("Premium");
  CHECK(fake.force_output);
  const auto* oh = dynamic_cast<const OpenHapticsDevice*>(dev.get());
  REQUIRE(oh != nullptr);
  CHECK(oh->nominal().max_force == 8.5);
  CHECK(oh->nominal().max_continuous_force == 1.4);
  CHECK(oh->nominal().max_stiffness == 3500.0);   // N/m: 3.5 N/mm x 1000 mm/m, exact
  CHECK(dev->limits().max_force == 8.5);           // the peak force is the clamp limit
  CHECK(oh->config_name() == "Premium");
  CHECK(dev->describe() == "phantom \"Premium\" (PHANTOM Premium 1.5)");
}

TEST_CASE("OpenHaptics: a nominal limit that is not a positive number refuses the device",
          "[hw][openhaptics]") {
  for (double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    Fresh fresh;
    auto& fake = hd_double::add_device("P");
    fake.max_continuous_force = bad;
    INFO("HD_NOMINAL_MAX_CONTINUOUS_FORCE = " << bad);
    CHECK_THROWS_WITH(make_openhaptics_device("P"),
                      Catch::Contains("\"P\"") &&
                          Catch::Contains("HD_NOMINAL_MAX_CONTINUOUS_FORCE") &&
                          Catch::Contains("not a positive number"));
    CHECK(fake.handle == HD_INVALID_HANDLE);   // disabled again, not left half open
    CHECK_FALSE(hd_double::scheduler_running());
  }
}

TEST_CASE("OpenHaptics: a device that fails to open names itself, the names tried and the error",
          "[hw][openhaptics]") {
  SECTION("a configured name whose device does not answer") {
    Fresh fresh;
    auto& fake = hd_double::add_device("Left Phantom");
    fake.init_error = HD_COMM_ERROR;
    fake.init_internal = 7;
    CHECK_THROWS_WITH(make_openhaptics_device("Left Phantom"),
                      Catch::Contains("OpenHaptics device \"Left Phantom\"") &&
                          Catch::Contains("names tried: \"Left Phantom\" -> HD_COMM_ERROR") &&
                          Catch::Contains("0x0302, internal 7") &&
                          Catch::Contains("Communication error"));
    // Any other name is tried alone: a typo never opens some other device.
    CHECK(hd_double::init_log() == std::vector<std::string>{"Left Phantom"});
  }
  SECTION("a name that is not configured") {
    Fresh fresh;
    hd_double::add_device("Right Phantom");
    CHECK_THROWS_WITH(make_openhaptics_device("Rigth Phantom"),
                      Catch::Contains("\"Rigth Phantom\"") &&
                          Catch::Contains("HD_COMM_CONFIG_ERROR"));
    CHECK(hd_double::init_log() == std::vector<std::string>{"Rigth Phantom"});
    CHECK(hd_double::device("Right Phantom").handle == HD_INVALID_HANDLE);
  }
  SECTION("the default device under all its names") {
    Fresh fresh;
    CHECK_THROWS_WITH(make_openhaptics_device("Default PHANToM"),
                      Catch::Contains("\"Default PHANToM\" -> HD_COMM_CONFIG_ERROR") &&
                          Catch::Contains("\"Default Device\" -> HD_COMM_CONFIG_ERROR") &&
                          Catch::Contains("HD_DEFAULT_DEVICE -> HD_COMM_CONFIG_ERROR"));
    CHECK(hd_double::init_log() ==
          std::vector<std::string>{"Default PHANToM", "Default Device", "<default>"});
    CHECK_FALSE(hd_double::scheduler_running());
  }
}

TEST_CASE("OpenHaptics: the default device opens under its other names", "[hw][openhaptics]") {
  Fresh fresh;
  hd_double::add_device("Default Device");   // the OpenHaptics 3.4+ name
  auto dev = make_openhaptics_device("Default PHANToM");   // the older name a scenario may use
  CHECK(hd_double::init_log() == std::vector<std::string>{"Default PHANToM", "Default Device"});
  CHECK(dynamic_cast<const OpenHapticsDevice&>(*dev).config_name() == "Default Device");
}

TEST_CASE("OpenHaptics: one scheduler callback serves two devices, each with its own data",
          "[hw][openhaptics]") {
  Fresh fresh;
  auto& thumb = hd_double::add_device("Thumb");
  auto& index = hd_double::add_device("Index");
  thumb.position_mm = {10.0, 20.0, 30.0};
  index.position_mm = {-5.0, 0.0, 5.0};
  index.max_force = 3.3;
  auto a = open_clamp_only(thumb, "Thumb");
  auto b = open_clamp_only(index, "Index");
  CHECK(hd_double::scheduled_callbacks() == 1);
  CHECK(hd_double::scheduler_running());
  CHECK(a->read(0, 0.0).position == expected_position(thumb.position_mm));
  CHECK(b->read(0, 0.0).position == expected_position(index.position_mm));

  const int thumb_frames = thumb.frames, index_frames = index.frames;
  a->render(Vec3(1.0, 0.0, 0.0));
  b->render(Vec3(0.0, 0.0, 10.0));   // above the Index's 3.3 N
  CHECK(hd_double::run_frames(5) == 5);   // five frames, one callback call each
  CHECK(thumb.frames == thumb_frames + 5);
  CHECK(index.frames == index_frames + 5);
  CHECK(as_vec(thumb.force) == as_vec(expected_hd_force(Vec3(1.0, 0.0, 0.0))));
  CHECK(index.force[1] <= 3.3);
  CHECK(index.force[1] >= 3.3 * (1.0 - 1e-14));

  // Closing one leaves the other served by the same single callback; its force went to zero
  // before it was disabled.
  a.reset();
  CHECK(thumb.handle == HD_INVALID_HANDLE);
  CHECK(as_vec(thumb.force) == Vec3::Zero());
  CHECK(hd_double::scheduled_callbacks() == 1);
  index.position_mm = {1.0, 2.0, 3.0};
  b->render(Vec3(0.0, 0.0, 1.0));
  hd_double::run_frames(1);
  CHECK(b->read(1, 0.001).position == expected_position(index.position_mm));
  CHECK(as_vec(index.force) == as_vec(expected_hd_force(Vec3(0.0, 0.0, 1.0))));
  b.reset();
  CHECK(as_vec(index.force) == Vec3::Zero());
  CHECK(hd_double::scheduled_callbacks() == 0);
  CHECK_FALSE(hd_double::scheduler_running());
}

TEST_CASE("OpenHaptics: the servo loop zeroes a force nobody renews", "[hw][openhaptics]") {
  // Law: the force stays on for kOpenHapticsStallFrames - 1 servo frames after the last request
  // and is zero from frame kOpenHapticsStallFrames on (counted in the device's own frames).
  Fresh fresh;
  auto& fake = hd_double::add_device("P");
  auto dev = open_clamp_only(fake, "P");
  const Vec3 f(0.5, 0.5, 0.5);
  dev->render(f);
  hd_double::run_frames(1);   // takes the request
  hd_double::run_frames(static_cast<int>(kOpenHapticsStallFrames) - 1);
  CHECK(as_vec(fake.force) == as_vec(expected_hd_force(f)));
  hd_double::run_frames(1);
  CHECK(as_vec(fake.force) == Vec3::Zero());
  // A new request brings it back.
  dev->render(f);
  hd_double::run_frames(1);
  CHECK(as_vec(fake.force) == as_vec(expected_hd_force(f)));
}

TEST_CASE("OpenHaptics: an HD error in a servo frame zeroes the force and read() reports it",
          "[hw][openhaptics]") {
  Fresh fresh;
  auto& fake = hd_double::add_device("P");
  auto dev = make_openhaptics_device("P");
  dev->render(Vec3(1.0, 1.0, 1.0));
  fake.frame_error = HD_EXCEEDED_MAX_VELOCITY;
  hd_double::run_frames(1);
  CHECK_THROWS_WITH(dev->read(0, 0.0), Catch::Contains("\"P\"") &&
                                           Catch::Contains("HD_EXCEEDED_MAX_VELOCITY") &&
                                           Catch::Contains("force is now zero"));
  hd_double::run_frames(1);
  CHECK(as_vec(fake.force) == Vec3::Zero());
  dev->render(Vec3(1.0, 1.0, 1.0));   // a faulted device stays at zero
  hd_double::run_frames(3);
  CHECK(as_vec(fake.force) == Vec3::Zero());
}
