// The OpenHaptics backend as a real device (hw/README.md, "Connecting Phantoms"), against the HD
// API test double: its clock (servo frames at HD_UPDATE_RATE) and frame numbers for the trace, and
// the force safety its servo callback applies (nominal peak and continuous force, ramp, stall,
// release). The double runs one servo frame per run_frames(1) on this thread: the device's time is
// its frame count, injected, never a wall clock.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "graspsim/hw/openhaptics_device.hpp"
#include "hd_double.hpp"

using graspsim::hw::Device;
using graspsim::hw::kOpenHapticsDefaultRate;
using graspsim::hw::kOpenHapticsStallFrames;
using graspsim::hw::make_openhaptics_device;
using graspsim::hw::OpenHapticsDevice;
using graspsim::hw::OpenHapticsOptions;
using graspsim::hw::Vec3;

namespace {

struct Fresh {
  Fresh() { hd_double::reset(); }
  ~Fresh() {
    for (const auto& v : hd_double::violations()) FAIL_CHECK("HD API misuse: " << v);
  }
};

double committed(const hd_double::FakeDevice& fake) {   // N: |force| at the last hdEndFrame
  return std::sqrt(fake.force[0] * fake.force[0] + fake.force[1] * fake.force[1] + fake.force[2] * fake.force[2]);
}

// The force safety law, written out independently of ForceSafety (hw/README.md "Force safety"),
// stepped once per servo frame at t_k = k / rate:
//   H_k = H_{k-1} + (1 - exp(-(t_k - t_{k-1}) / tau)) (|F_{k-1}|^2 - H_{k-1})
//   L_k = min(P min(1, (t_k - t_0) / T_rise), sqrt(max(0, P^2 - (P^2 - C^2) H_k / C^2)))
struct Law {
  double p, c, tau, rise, t0;
  double heat = 0.0, last_t = 0.0, last_sq = 0.0;   // frame 0 (the factory's) rendered zero at t = 0
  double limit(double t) {
    heat += (1.0 - std::exp(-(t - last_t) / tau)) * (last_sq - heat);
    last_t = t;
    const double ramp = rise > 0.0 ? p * std::min(1.0, (t - t0) / rise) : p;
    return std::min(ramp, std::sqrt(std::max(0.0, p * p - (p * p - c * c) * heat / (c * c))));
  }
  void sent(double f) { last_sq = f * f; }
};

}  // namespace

TEST_CASE("OpenHaptics: device time is the servo frame over HD_UPDATE_RATE and frames are counted per read",
          "[hw][openhaptics][clock]") {
  // Rates: 1 kHz (HD's default), 500 Hz, and 0 (HD gives no rate: the default 1 kHz is assumed).
  const int reported = GENERATE(1000, 500, 0);
  const double rate = reported > 0 ? reported : kOpenHapticsDefaultRate;
  INFO("HD_UPDATE_RATE " << reported);
  Fresh fresh;
  auto& fake = hd_double::add_device("P");
  fake.update_rate = reported;
  auto dev = make_openhaptics_device("P");
  const auto* oh = dynamic_cast<const OpenHapticsDevice*>(dev.get());
  // Its clock and sample numbers, through the device interface.
  const graspsim::hw::Device* clock = dev.get();
  const graspsim::hw::Device* counter = dev.get();
  REQUIRE(oh);
  REQUIRE(clock->has_sample_clock());
  CHECK(oh->rate() == rate);
  // The factory served frame 0: the first read is that frame's sample, the one frame so far.
  dev->read(0, 0.0);
  CHECK(counter->sample_sequence() == 0);
  CHECK(counter->new_samples() == 1);
  CHECK(clock->sample_time() == 0.0);
  // Reads between frames (graspsim faster than the device) hold: 0 new frames, the same time.
  // Several frames between reads (graspsim slower, or a late read) count them all. Frame k's
  // time is k / rate, one IEEE division: compared exactly.
  std::int64_t frame = 0;
  for (const int frames : {1, 0, 0, 3, 1, 0, 250}) {
    hd_double::run_frames(frames);
    frame += frames;
    fake.position_mm = {static_cast<double>(frame), 0.0, 0.0};   // unused: the sample is the frame's
    dev->read(1, 0.0);
    INFO("after " << frames << " more frames");
    CHECK(counter->sample_sequence() == frame);
    CHECK(counter->new_samples() == frames);
    CHECK(clock->sample_time() == static_cast<double>(frame) / rate);
  }
}

// The thermal law through the render path: a saturated request (100 N) rendered before every
// servo frame from cold, 30 s of frames, for the nominal figures of a Premium 1.5 (8.5 / 1.4 N)
// and a Touch (3.3 / 0.88 N), at 1 kHz and 500 Hz, tau 10 s and 2 s. The force committed in
// each frame is the law's limit recomputed above, to 1e-12 P (rounding only: expm1 vs exp, the
// clamp's 4 ulp, and a contracting recursion that does not accumulate them). Then the law's
// long-run claims: the force ends at C (time constant tau C^2 / P^2 <= 0.71 s, so after 30 s
// only rounding is left: 1e-9 C), and the motor heat, the exponentially weighted mean square of
// the committed forces (recomputed here from them), never exceeds C^2 (1e-12, rounding).
TEST_CASE("OpenHaptics: committed forces follow the peak ramp and thermal continuous limit the device reports",
          "[hw][openhaptics][safety]") {
  const auto [p, c] = GENERATE(std::pair{8.5, 1.4}, std::pair{3.3, 0.88});
  const int rate = GENERATE(1000, 500);
  const double tau = GENERATE(10.0, 2.0);
  INFO("P " << p << " N, C " << c << " N, " << rate << " Hz, tau " << tau << " s");
  Fresh fresh;
  auto& fake = hd_double::add_device("P");
  fake.max_force = p;
  fake.max_continuous_force = c;
  fake.update_rate = rate;
  OpenHapticsOptions options;
  options.thermal_time_constant = tau;
  auto dev = make_openhaptics_device("P", options);   // frame 0 served, no request
  const Vec3 dir = Vec3(-1.0, 3.0, 2.0).normalized();
  Law law{p, c, tau, options.rise_time, 1.0 / rate};   // the first request is taken in frame 1
  double worst = 0.0, heat = 0.0, worst_heat = 0.0, last = 0.0, peak_seen = 0.0;
  const int frames = 30 * rate;
  for (int k = 1; k <= frames; ++k) {
    dev->render(100.0 * dir);
    hd_double::run_frames(1);
    const double f = committed(fake);
    const double expected = law.limit(static_cast<double>(k) / rate);
    law.sent(expected);
    worst = std::max(worst, std::abs(f - expected));
    peak_seen = std::max(peak_seen, f);
    heat += -std::expm1(-1.0 / rate / tau) * (last * last - heat);   // |F| held over the frame before
    worst_heat = std::max(worst_heat, heat);
    last = f;
  }
  INFO("largest |F - L| " << worst << " N");
  CHECK(worst <= 1e-12 * p);
  CHECK(peak_seen <= p);
  CHECK(last == Approx(c).epsilon(1e-9));
  CHECK(worst_heat <= c * c * (1.0 + 1e-12));
  CHECK(heat == Approx(c * c).epsilon(1e-9));
}

// Release, and the servo's own stall, re-arm the ramp: a 0.5 N push (under C, so only the ramp
// limits it) rises as P (k - k0) / (rate T_rise) from the frame k0 that took the request, is
// committed whole once the ramp passes it, is zero from the frame after release(), and rises from
// zero again from the first request after it; the same after a stall (no request for
// kOpenHapticsStallFrames frames), where without the ramp it would come back at full force at once.
TEST_CASE("OpenHaptics: after a release or a stall forces ramp in again", "[hw][openhaptics][safety]") {
  Fresh fresh;
  auto& fake = hd_double::add_device("P");   // 8.5 N peak, 1.4 N continuous, 1 kHz
  auto dev = make_openhaptics_device("P");   // T_rise 1 s
  const Vec3 push(0.0, 0.0, 0.5);
  const double p = fake.max_force, rate = 1000.0, rise = OpenHapticsOptions{}.rise_time;
  auto ramp_in = [&](const char* what) {
    INFO(what);
    for (int k = 0; k < 150; ++k) {
      dev->render(push);
      hd_double::run_frames(1);
      const double expected = std::min(0.5, p * (k / rate) / rise);
      if (std::abs(committed(fake) - expected) > 1e-12) {
        CHECK(committed(fake) == Approx(expected).margin(1e-12));
        return;
      }
    }
    CHECK(committed(fake) == 0.5);   // whole
  };
  ramp_in("start");
  dev->release();
  hd_double::run_frames(1);
  CHECK(committed(fake) == 0.0);
  hd_double::run_frames(20);
  CHECK(committed(fake) == 0.0);
  ramp_in("after release");
  hd_double::run_frames(static_cast<int>(kOpenHapticsStallFrames));   // no request: stalled
  CHECK(committed(fake) == 0.0);
  ramp_in("after a stall");
}

TEST_CASE("OpenHaptics: a continuous force above the peak refuses the device naming both", "[hw][openhaptics]") {
  Fresh fresh;
  auto& fake = hd_double::add_device("P");
  fake.max_continuous_force = 9.0;   // above the 8.5 N peak
  CHECK_THROWS_WITH(make_openhaptics_device("P"), Catch::Contains("\"P\"") && Catch::Contains("continuous_force") &&
                                                      Catch::Contains("peak_force"));
  CHECK(hd_double::device("P").handle == HD_INVALID_HANDLE);   // closed again
}
