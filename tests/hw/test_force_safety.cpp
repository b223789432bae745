// Tests of ForceSafety (force_safety.hpp): the rendered force never exceeds the current limit
// for any request; the ramp, the thermal derating and the stall and release rules follow their
// stated laws. Time is injected: the tests drive the device clock on a fixed grid.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "graspsim/hw/device_models.hpp"
#include "graspsim/hw/force_safety.hpp"
#include "tests/support/random.hpp"

using namespace graspsim::hw;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDenorm = std::numeric_limits<double>::denorm_min();

using graspsim::test::random_direction;   // tests/support/random.hpp
using graspsim::test::uniform01;

// A request of the sweep: random directions with magnitudes log-uniform over 1e-320..1e308 N,
// and one in four an extreme: NaN or infinite components, DBL_MAX, 1e308, denormals, zero.
Vec3 random_request(std::mt19937_64& rng) {
  const std::uint64_t pick = rng() % 16;
  const Vec3 dir = random_direction(rng);
  switch (pick) {
    case 0: return Vec3(kNaN, 1.0, 0.0);
    case 1: return Vec3(0.0, -kInf, 0.0);
    case 2: return Vec3(DBL_MAX, -DBL_MAX, DBL_MAX);
    case 3: return dir * 1e308;
    case 4: return Vec3(kDenorm, -kDenorm, 4.0 * kDenorm);
    case 5: return Vec3::Zero();
    case 6: return Vec3(kInf, kNaN, -kInf);
    default: return dir * std::pow(10.0, -320.0 + 628.0 * uniform01(rng));
  }
}

// The limit law written out again, from the heat the test itself integrates (independent of
// the class's state): L = min(P min(1, (t - t0) / T_rise), sqrt(P^2 - (P^2 - C^2) H / C^2)).
double law_limit(const ForceSafetyConfig& c, double t, double t0, double heat) {
  const double p = c.peak_force, k = c.continuous_force;
  const double ramp = c.rise_time > 0.0 ? p * std::clamp((t - t0) / c.rise_time, 0.0, 1.0) : p;
  return std::min(ramp, std::sqrt(std::max(0.0, p * p - (p * p - k * k) * heat / (k * k))));
}

}  // namespace

// Property: over 200,000 device ticks with random requests (extremes included), random gaps
// (some longer than the stall timeout) and random releases, every output is finite, its
// magnitude never exceeds the limit of the law (recomputed here from the outputs seen, exact
// comparison but for 1e-12 relative: the law and the class round differently) nor the peak
// (exact), a non-finite request renders exactly zero, and the heat never exceeds C^2.
TEST_CASE("ForceSafety: no request, however extreme, renders above the current limit",
          "[hw][force_safety][law]") {
  for (const DeviceModel& model : device_models()) {
    INFO(model.name);
    ForceSafetyConfig c;
    c.peak_force = model.peak_force;
    c.continuous_force = model.continuous_force;
    // s: short, so the sweep spends time derated too, yet long enough for the longest gap of
    // the sweep (31 ms) to keep a P^2 <= C^2, the condition for H <= C^2 (force_safety.hpp).
    c.thermal_time_constant = 2.0;
    c.rise_time = 0.05;
    c.stall_timeout = 0.01;
    ForceSafety safety(c);
    std::mt19937_64 rng(0x5eedULL + static_cast<std::uint64_t>(model.peak_force * 10));
    double t = 0.0, t_prev = 0.0, heat = 0.0, last_sq = 0.0, t0 = 0.0, last_request = -1.0;
    bool active = false, first = true;
    int nonfinite = 0, clamped = 0, derated = 0, failures = 0;
    for (int k = 0; k < 50000 && failures < 5; ++k) {
      // Device clock: 1 ms ticks, now and then a gap of up to 30 ms (past the stall timeout).
      t += (rng() % 50 == 0) ? 0.001 * static_cast<double>(1 + rng() % 30) : 0.001;
      if (!first) heat += -std::expm1(-(t - t_prev) / c.thermal_time_constant) * (last_sq - heat);
      first = false;
      t_prev = t;
      if (rng() % 500 == 0) {
        safety.release();
        active = false;
      }
      bool nonfinite_request = false;
      if (rng() % 3 != 0) {   // two ticks in three bring a request
        const Vec3 f = random_request(rng);
        nonfinite_request = !f.allFinite();
        if (!active || t - last_request > c.stall_timeout) t0 = t;
        active = true;
        last_request = t;
        const Vec3 now = safety.request(f, t);
        if (nonfinite_request) CHECK((now.array() == 0.0).all());
        if (nonfinite_request) ++nonfinite;
      }
      if (active && t - last_request > c.stall_timeout) active = false;
      const Vec3 out = safety.output(t);
      const double limit = active ? law_limit(c, t, t0, heat) : 0.0;
      const double mag = out.norm();
      last_sq = out.squaredNorm();
      const bool ok = out.allFinite() && mag <= c.peak_force && mag <= limit * (1.0 + 1e-12) &&
                      (!nonfinite_request || mag == 0.0) && safety.heat() <= c.continuous_force *
                      c.continuous_force * (1.0 + 1e-12);
      if (!ok) {
        ++failures;
        FAIL_CHECK("t = " << t << " s: |out| = " << mag << " N, law limit " << limit
                          << " N, heat " << safety.heat() << " N^2");
      }
      if (mag > 0.0 && mag < c.peak_force * 0.999 && std::abs(mag - limit) < 1e-9 * c.peak_force)
        ++clamped;
      if (limit < c.peak_force * 0.999 && t - t0 > c.rise_time) ++derated;
    }
    CHECK(failures == 0);
    // The sweep reached the interesting regimes: non-finite requests, outputs held at a limit
    // below the peak (ramping or derated), and derated ticks.
    CHECK(nonfinite > 1000);
    CHECK(clamped > 1000);
    CHECK(derated > 1000);
  }
}

// Ramp: L(t) = P (t - t0) / T_rise for t0 <= t <= t0 + T_rise, then P. With the thermal model
// out of the way (C = P) and a request far above the peak, the output magnitude is the ramp
// itself; clamp_force lands 4 ulp short of the limit, so 1e-14 relative is the tolerance.
TEST_CASE("ForceSafety: the limit ramps in linearly over the rise time",
          "[hw][force_safety][law]") {
  for (double rise : {0.01, 0.1, 1.0}) {   // s
    ForceSafetyConfig c;
    c.peak_force = 8.5;
    c.continuous_force = 8.5;
    c.rise_time = rise;
    ForceSafety safety(c);
    const double t0 = 0.25;   // s: the first request starts the ramp
    const Vec3 dir = Vec3(1.0, -2.0, 2.0) / 3.0;
    for (int k = 0; k <= 2000; ++k) {
      const double t = t0 + k * 1e-3;
      safety.request(dir * 100.0, t);
      const double got = safety.output(t).norm();
      const double want = c.peak_force * std::min(1.0, (t - t0) / rise);
      INFO("rise " << rise << " s, t - t0 = " << t - t0 << " s");
      REQUIRE(std::abs(got - want) <= 1e-14 * c.peak_force);
    }
  }
}

// Thermal derating under saturated demand from cold (no ramp). The discrete scheme the class
// uses: F_k at the limit L_k, then H_{k+1} = H_k + a (L_k^2 - H_k), a = 1 - exp(-dt / tau), with
// L_k^2 = P^2 - (P^2 - C^2) H_k / C^2, gives H_{k+1} = aP^2 + (1 - aP^2/C^2) H_k, so
//   H_k = C^2 (1 - r^k),  r = 1 - a P^2 / C^2          (the discrete law, to rounding: 1e-12)
// and in continuous time H(t) = C^2 (1 - exp(-t / tau')), tau' = tau C^2 / P^2. With
// y = a P^2 / C^2, r^k = exp(-k y (1 + y/2 + ...)), which differs from exp(-k y) by at most
// about y / (2e) of C^2 (the maximum over k of k y^2/2 exp(-k y)), plus the a-vs-dt/tau term of
// the same order: the tolerance on H / C^2 is y (about 4e-3 for the Premium at tau = 1 s).
// The output tends to C: after 20 tau' it is C to 1e-6 relative.
TEST_CASE("ForceSafety: the thermal model derates from the peak to the continuous force",
          "[hw][force_safety][law]") {
  for (const DeviceModel& model : device_models()) {
    for (double tau : {1.0, 10.0}) {   // s
      ForceSafetyConfig c;
      c.peak_force = model.peak_force;
      c.continuous_force = model.continuous_force;
      c.thermal_time_constant = tau;
      c.rise_time = 0.0;
      ForceSafety safety(c);
      const double dt = 1e-3, p2 = c.peak_force * c.peak_force;
      const double c2 = c.continuous_force * c.continuous_force;
      const double a = -std::expm1(-dt / tau);
      const double y = a * p2 / c2;
      const double tau_eff = tau * c2 / p2;
      const auto steps = static_cast<int>(std::ceil(20.0 * tau_eff / dt));
      double worst_discrete = 0.0, worst_continuous = 0.0;
      Vec3 out = Vec3::Zero();
      for (int k = 0; k <= steps; ++k) {
        const double t = k * dt;
        safety.request(Vec3(0.0, 0.0, -1e6), t);
        out = safety.output(t);
        const double h_discrete = c2 * (1.0 - std::pow(1.0 - y, k));
        const double h_continuous = c2 * -std::expm1(-t / tau_eff);
        worst_discrete = std::max(worst_discrete, std::abs(safety.heat() - h_discrete) / c2);
        worst_continuous = std::max(worst_continuous, std::abs(safety.heat() - h_continuous) / c2);
        const double l2 = p2 - (p2 - c2) * safety.heat() / c2;
        REQUIRE(std::abs(out.norm() - std::sqrt(l2)) <= 1e-12 * c.peak_force);
      }
      INFO(model.name << ", tau " << tau << " s: |H - discrete| / C^2 = " << worst_discrete
                      << ", |H - continuous| / C^2 = " << worst_continuous << " (tol " << y << ")");
      CHECK(worst_discrete <= 1e-12);
      CHECK(worst_continuous <= y);
      CHECK(std::abs(out.norm() - c.continuous_force) <= 1e-6 * c.continuous_force);
    }
  }
}

// Stall: with requests every 1 ms until t_last, the output holds the last request while
// t - t_last <= timeout and is zero after; the next request ramps in again from zero.
TEST_CASE("ForceSafety: a stalled loop renders zero, and the force ramps in again after it",
          "[hw][force_safety][law]") {
  for (double timeout : {0.005, 0.05}) {   // s
    ForceSafetyConfig c;
    c.rise_time = 0.1;
    c.stall_timeout = timeout;
    ForceSafety safety(c);
    const Vec3 f(0.5, 0.0, 0.0);   // N: below every limit once ramped in
    const int last = 300;          // ms: the last request
    for (int k = 0; k <= 600; ++k) {
      const double t = k * 1e-3;
      if (k <= last) safety.request(f, t);
      const Vec3 out = safety.output(t);
      INFO("timeout " << timeout << " s, t = " << t << " s");
      if (k >= 200 && k <= last) REQUIRE(out == f);   // ramped in: untouched
      if (k > last && t - last * 1e-3 <= timeout - 1e-9) REQUIRE(out == f);   // held
      if (t - last * 1e-3 > timeout + 1e-9) REQUIRE(out.norm() == 0.0);     // stalled
    }
    CHECK_FALSE(safety.active());
    // Recovery ramps in again: right after, the limit is 0; half a rise time (50 ms of requests
    // every ms) later, P / 2.
    safety.request(f * 100.0, 0.7);
    CHECK(safety.output(0.7).norm() == 0.0);
    for (int k = 701; k <= 750; ++k) safety.request(f * 100.0, k * 1e-3), safety.output(k * 1e-3);
    CHECK(std::abs(safety.output(0.75).norm() - 0.5 * c.peak_force) <= 1e-12 * c.peak_force);
  }
}

TEST_CASE("ForceSafety: release renders zero at once and the next request ramps in again",
          "[hw][force_safety][law]") {
  ForceSafetyConfig c;
  c.rise_time = 0.2;
  ForceSafety safety(c);
  for (int k = 0; k <= 500; ++k) safety.request(Vec3(0.0, 1.0, 0.0), k * 1e-3), safety.output(k * 1e-3);
  CHECK(safety.output(0.5).norm() == 1.0);
  safety.release();
  CHECK(safety.output(0.5).norm() == 0.0);
  CHECK(safety.output(0.501).norm() == 0.0);
  CHECK(safety.limit(0.501) == 0.0);
  safety.request(Vec3(0.0, 100.0, 0.0), 0.6);
  CHECK(safety.output(0.6).norm() == 0.0);
  CHECK(std::abs(safety.limit(0.64) - 0.2 * c.peak_force) <= 1e-12 * c.peak_force);
  CHECK(safety.limit(0.651) == 0.0);   // no request for 51 ms: stalled
  // A non-finite clock is a fault: nothing is rendered.
  CHECK(safety.output(kNaN).norm() == 0.0);
  CHECK(safety.request(Vec3(1.0, 0.0, 0.0), kInf).norm() == 0.0);
  CHECK_FALSE(safety.active());
}

TEST_CASE("ForceSafety: a bad configuration names the field", "[hw][force_safety][errors]") {
  const auto message = [](ForceSafetyConfig c) {
    try {
      ForceSafety s(c);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  ForceSafetyConfig c;
  c.peak_force = kNaN;
  CHECK_THAT(message(c), Catch::Contains("peak_force"));
  c = {};
  c.continuous_force = 9.0;   // above the peak
  CHECK_THAT(message(c), Catch::Contains("continuous_force"));
  c = {};
  c.thermal_time_constant = 0.0;
  CHECK_THAT(message(c), Catch::Contains("thermal_time_constant"));
  c = {};
  c.rise_time = -1.0;
  CHECK_THAT(message(c), Catch::Contains("rise_time"));
  c = {};
  c.stall_timeout = kInf;
  CHECK_THAT(message(c), Catch::Contains("stall_timeout"));
}

TEST_CASE("device_model: the table holds the four models and an unknown name lists them",
          "[hw][device_models]") {
  CHECK(device_models().size() == 4);
  const DeviceModel& premium = device_model("premium-1.5");
  CHECK(&device_model("Phantom Premium 1.5") == &premium);
  // The Premium 1.5's figures (hw/README.md, "Device models").
  CHECK(premium.peak_force == 8.5);
  CHECK(premium.continuous_force == 1.4);
  CHECK(premium.tip_mass == 0.075);
  CHECK(premium.backdrive_friction == 0.04);
  CHECK(premium.encoder_resolution == Approx(3e-5).epsilon(1e-12));
  for (const DeviceModel& m : device_models()) {
    INFO(m.name);
    CHECK(m.continuous_force < m.peak_force);
    CHECK((m.workspace.array() > 0.0).all());
    CHECK(m.tip_mass > 0.0);
    CHECK(m.encoder_resolution > 0.0);
    CHECK(m.device_rate_hz > 0.0);
  }
  try {
    device_model("phantom");
    FAIL("no error");
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK_THAT(what, Catch::Contains("\"phantom\""));
    for (const char* key : {"premium-1.5", "premium-1.5-hf", "omni", "touch"})
      CHECK_THAT(what, Catch::Contains(key));
  }
}

// The stall rule's exact boundary: the force is held while time - last request <= stall_timeout,
// and zero once it is more (force_safety.hpp). Times chosen exact in binary (request at 0.5 s,
// timeout 0.25 s): at 0.75 s the force is still held; at the next double above 0.75 s it is zero,
// and limit() agrees. A rule that stalled at the timeout itself (>=) fails the first check, one
// that waited a tick more the second.
TEST_CASE("ForceSafety: the stall boundary is exact: held at the timeout, zero just past it",
          "[hw][force_safety][law]") {
  ForceSafetyConfig c;
  c.rise_time = 0.0;
  c.stall_timeout = 0.25;
  const Vec3 f(0.5, 0.0, 0.0);   // N: below every limit
  {
    ForceSafety safety(c);
    safety.request(f, 0.5);
    CHECK(safety.limit(0.75) > 0.0);
    CHECK(safety.output(0.75) == f);
  }
  {
    ForceSafety safety(c);
    safety.request(f, 0.5);
    const double past = std::nextafter(0.75, 1.0);
    CHECK(safety.limit(past) == 0.0);
    CHECK(safety.output(past).norm() == 0.0);
    CHECK_FALSE(safety.active());
  }
}

// The one ramp law (force_safety.hpp): r(t) = min(1, t / T_rise), 0 before the start, 1 when
// T_rise = 0. Swept over rise times and times before, at and after the rise; compared exactly:
// r must be t / T itself while t < T (the same double operation as the law) and exactly 1 after.
// It can fail: a ramp that started from 1, or used (t - dt) / T, differs at some of these times.
TEST_CASE("Force ramp: one law, r = min(1, t / T_rise)", "[hw][force_safety][law]") {
  using graspsim::hw::ramp_fraction;
  for (double rise : {0.1, 0.5, 2.0}) {
    for (double t : {0.0, 0.25 * rise, 0.5 * rise, std::nextafter(rise, 0.0), rise, 1.5 * rise, 10.0}) {
      INFO("T_rise = " << rise << " s, t = " << t << " s");
      const double r = ramp_fraction(t, rise);
      if (t < rise) CHECK(r == t / rise);
      else CHECK(r == 1.0);
    }
  }
  CHECK(ramp_fraction(0.0, 0.0) == 1.0);    // no ramp: full force from the start
  CHECK(ramp_fraction(-1.0, 1.0) == 0.0);   // before the ramp's start: nothing
}
