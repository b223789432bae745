// UdpDevice as a real device (hw/README.md, "UDP protocol"): its own clock and sample numbering for
// the trace (hw::Device::sample_time, sample_sequence, new_samples), and the device's force limits (peak, thermal
// continuous limit, ramp, release) applied to what it sends (hw/README.md "Force safety").
// Every case runs on loopback against the in-process peer in lockstep, with graspsim's time
// injected through read(tick, time): no wall clock decides anything.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "graspsim/hw/device_models.hpp"
#include "graspsim/hw/mapped_device.hpp"
#include "graspsim/hw/udp_device.hpp"
#include "tests/hw/udp_peer.hpp"

using namespace graspsim::hw;
using graspsim::test::line_sample;
using graspsim::test::UdpPeer;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

Vec3 as_vec(const udp::Force& f) { return Vec3(f.force[0], f.force[1], f.force[2]); }

UdpDeviceConfig lockstep(const UdpPeer& peer, const ForceSafetyConfig& safety, double timeout_s = 0.05) {
  UdpDeviceConfig c{"127.0.0.1", peer.port(), 0, timeout_s, DeviceLimits{1e3}};
  c.lockstep = true;
  c.safety = safety;
  return c;
}

// The force safety law written out again, independently of ForceSafety (hw/README.md):
//   H_n = H_{n-1} + (1 - exp(-(t_n - t_{n-1}) / tau)) (|F_{n-1}|^2 - H_{n-1})   (F held over the tick)
//   L_n = min(P min(1, (t_n - t_0) / T_rise), sqrt(max(0, P^2 - (P^2 - C^2) H_n / C^2)))
// for a request held from t_0 on; the force sent is the request shortened to L_n.
struct Law {
  ForceSafetyConfig c;
  double t0 = 0.0;       // s: start of the ramp
  double heat = 0.0;     // N^2: H
  double last_t = 0.0;   // s
  double last_sq = 0.0;  // N^2: |F|^2 sent at last_t
  bool started = false;
  double limit(double t) {   // N: L at t, advancing H to t first
    if (started) heat += (1.0 - std::exp(-(t - last_t) / c.thermal_time_constant)) * (last_sq - heat);
    started = true;
    last_t = t;
    const double p = c.peak_force, k = c.continuous_force;
    const double ramp = c.rise_time > 0.0 ? p * std::min(1.0, (t - t0) / c.rise_time) : p;
    return std::min(ramp, std::sqrt(std::max(0.0, p * p - (p * p - k * k) * heat / (k * k))));
  }
  void sent(double magnitude) { last_sq = magnitude * magnitude; }
};

}  // namespace

TEST_CASE("UdpDevice: device time sequence number and new samples per read for the trace",
          "[hw][udp][loopback][clock]") {
  UdpPeer peer;
  ForceSafetyConfig s;
  UdpDevice d(lockstep(peer, s));
  peer.receive_hello();
  CHECK(d.sample_sequence() == -1);   // before any sample
  CHECK(d.new_samples() == 0);
  // What the peer sends before each read, and what that read must report: the newest sample's
  // own device time and number, and how many new samples it accepted (0 = held).
  struct Step {
    std::vector<std::uint32_t> send;
    std::int64_t sequence, fresh;
  };
  const Step steps[] = {
      {{0}, 0, 1},        // the first sample
      {{1, 2}, 2, 2},     // two in one servo tick (a device faster than the servo)
      {{2}, 2, 0},        // a duplicate: held
      {{5}, 5, 1},        // 3 and 4 lost: the number jumps, one new sample
      {{4}, 5, 0},        // 4 arrives late: dropped, held
      {{6, 7, 8}, 8, 3},  // three at once
  };
  std::int64_t tick = 0;
  for (const Step& step : steps) {
    for (std::uint32_t n : step.send) peer.send(line_sample(n));
    d.read(tick, tick / 1000.0);
    INFO("tick " << tick);
    CHECK(d.sample_sequence() == step.sequence);
    CHECK(d.new_samples() == step.fresh);
    // The device's clock, bit for bit from the datagram (line_sample: n ms), not graspsim's.
    CHECK(same_bits(d.sample_time(), line_sample(static_cast<std::uint32_t>(step.sequence)).device_time));
    d.render(Vec3::Zero());
    peer.receive_force();
    ++tick;
  }
}

// The thermal law through the render path: a saturated demand (100 N) from cold, read and
// rendered at 1 kHz for 30 s. Each force the server receives must be the law's limit (recomputed
// above), in the direction asked. Tolerance 1e-12 P: the two computations differ only in rounding
// (expm1 vs exp, 4 ulp of shortening in clamp_force), and the recursion is a contraction, so
// rounding does not accumulate past a few ulp of H. Then the law's long-run claims: the force
// settles at the continuous limit C (time constant tau C^2 / P^2 <= 0.71 s here, so after 30 s
// the distance is e^-40 of P: rounding only, tolerance 1e-9 C), and the motor's heat, the
// exponentially weighted mean square of the forces received (time constant tau, computed here
// from what the server got), never exceeds C^2 (tolerance 1e-12 relative: rounding) and ends at
// C^2. (A plain mean square over a window is not bounded by C^2: under saturation |F| falls to C
// from above, so every window's mean square is slightly above C^2; the heat is the budget.)
TEST_CASE("UdpDevice: forces sent follow the peak ramp and thermal continuous limit of its model",
          "[hw][udp][loopback][safety]") {
  const char* model = GENERATE("premium-1.5", "touch");
  const double tau = GENERATE(10.0, 2.0);
  ForceSafetyConfig s = udp_safety_of_model(model);
  s.thermal_time_constant = tau;
  INFO(model << ", tau " << tau << " s");
  UdpPeer peer;
  UdpDevice d(lockstep(peer, s));
  peer.receive_hello();
  Law law{s};
  const Vec3 dir = Vec3(2.0, -1.0, 0.5).normalized();
  const int ticks = 30000;
  double worst = 0.0, worst_direction = 0.0, peak_seen = 0.0, last = 0.0;
  double heat = 0.0, worst_heat = 0.0;   // N^2
  for (int n = 0; n < ticks; ++n) {
    const double t = n * 1e-3;
    peer.send(line_sample(static_cast<std::uint32_t>(n)));
    d.read(n, t);
    d.render(100.0 * dir);
    const Vec3 f = as_vec(peer.receive_force());
    const double expected = law.limit(t);   // the request (100 N) is always above it
    law.sent(expected);
    worst = std::max(worst, std::abs(f.norm() - expected));
    if (f.norm() > 0.0) worst_direction = std::max(worst_direction, (f.normalized() - dir).norm());
    peak_seen = std::max(peak_seen, f.norm());
    if (n > 0) heat += -std::expm1(-1e-3 / tau) * (last * last - heat);   // |F| held over the tick before
    worst_heat = std::max(worst_heat, heat);
    last = f.norm();
  }
  INFO("largest |F - L| " << worst << " N");
  CHECK(worst <= 1e-12 * s.peak_force);
  CHECK(worst_direction <= 1e-15);   // the direction asked, to rounding
  CHECK(peak_seen <= s.peak_force);
  CHECK(last == Approx(s.continuous_force).epsilon(1e-9));
  const double c2 = s.continuous_force * s.continuous_force;
  CHECK(worst_heat <= c2 * (1.0 + 1e-12));
  CHECK(heat == Approx(c2).epsilon(1e-9));
  // The safety's own state agrees: H reached C^2.
  CHECK(d.safety().heat() == Approx(s.continuous_force * s.continuous_force).epsilon(1e-9));
}

// Release re-arms the ramp (Device::on_release): a 1 N push (under C, so only the ramp limits it)
// ramps in as L = P (t - t0) / T_rise from the first render (t0), is sent whole once the ramp
// passes 1 N, drops to zero at release(), and ramps in again from the first render after it,
// not back to 1 N at once. The same through a MappedDevice (rotated 90 degrees about z), which
// must forward the release to the device it wraps. After a link loss the force ramps in again too.
TEST_CASE("UdpDevice: after a release or a link loss forces ramp in again", "[hw][udp][loopback][safety]") {
  const bool mapped = GENERATE(false, true);
  INFO((mapped ? "through a MappedDevice" : "the UdpDevice itself"));
  ForceSafetyConfig s = udp_safety_of_model("premium-1.5");   // P 8.5 N, T_rise 1 s
  UdpPeer peer;
  auto owned = std::make_unique<UdpDevice>(lockstep(peer, s, 0.05));
  UdpDevice& udp_device = *owned;
  WorkspaceMapping m;
  m.rotation = Vec3(0.0, 0.0, std::acos(-1.0) / 2.0);
  std::unique_ptr<Device> dev = mapped ? std::unique_ptr<Device>(std::make_unique<MappedDevice>(std::move(owned), m))
                                       : std::unique_ptr<Device>(std::move(owned));
  peer.receive_hello();
  const Vec3 push(0.0, 1.0, 0.0);   // N
  std::uint32_t seq = 0;
  int tick = 0;
  // One servo tick at 1 kHz: a new sample (unless `drop`, then a duplicate), read, render.
  auto step = [&](bool drop = false) {
    peer.send(line_sample(drop ? seq - 1 : seq++));
    dev->read(tick, tick * 1e-3);
    dev->render(push);
    ++tick;
    return as_vec(peer.receive_force()).norm();
  };
  // A ramp from t0: |F| at tick n is min(1 N, P (n - n0) ms / T_rise) (within rounding).
  auto ramp_from = [&](int n0, const char* what) {
    INFO(what);
    for (int k = 0; k < 200; ++k) {
      const double expected = std::min(1.0, s.peak_force * (k * 1e-3) / s.rise_time);
      const double got = step();
      if (std::abs(got - expected) > 1e-12) {
        CHECK(got == Approx(expected).margin(1e-12));
        return;
      }
    }
    CHECK(tick - n0 == 200);
  };
  ramp_from(0, "start");
  // Whole (exactly, or to the rotation's rounding through the mapping).
  for (int k = 0; k < 300; ++k) CHECK(std::abs(step() - 1.0) <= (mapped ? 4e-16 : 0.0));
  dev->release();
  // The zero; through the mapping a second one, from forwarding release() to the device inside.
  for (int k = 0; k < (mapped ? 2 : 1); ++k) {
    CHECK(as_vec(peer.receive_force()).norm() == 0.0);
    peer.send(line_sample(seq++));   // lockstep: the peer answers every datagram
  }
  ramp_from(tick, "after release");
  // A link loss: duplicates only, past the 0.05 s timeout, then samples again.
  for (int k = 0; k < 80; ++k) step(/*drop=*/true);
  CHECK(udp_device.link_lost());
  ramp_from(tick, "after a link loss");
}

TEST_CASE("parse_udp_spec: device model and explicit force limits", "[hw][udp][spec]") {
  // Default: the weakest model of the table (kUdpDefaultModel).
  UdpDeviceConfig c = parse_udp_spec("127.0.0.1:7001");
  CHECK(std::string(kUdpDefaultModel) == "touch");
  CHECK(c.safety.peak_force == device_model("touch").peak_force);
  CHECK(c.safety.continuous_force == device_model("touch").continuous_force);
  c = parse_udp_spec("udp:h:1,model=premium-1.5");
  CHECK(c.safety.peak_force == 8.5);
  CHECK(c.safety.continuous_force == 1.4);
  CHECK(c.model == "premium-1.5");
  // Explicit figures replace the model's, in either order.
  c = parse_udp_spec("h:1,max_force=6,model=premium-1.5-hf,continuous_force=2.5");
  CHECK(c.safety.peak_force == 6.0);
  CHECK(c.safety.continuous_force == 2.5);
  c = parse_udp_spec("h:1,max_force=3");   // touch's 0.88 N continuous stays
  CHECK(c.safety.peak_force == 3.0);
  CHECK(c.safety.continuous_force == device_model("touch").continuous_force);
  const std::pair<const char*, const char*> bad[] = {
      {"h:1,model=phantom-9", "model: "},
      {"h:1,model=", "model: "},
      {"h:1,max_force=0", "max_force '0' is not a positive number of newtons"},
      {"h:1,max_force=inf", "max_force 'inf'"},
      {"h:1,continuous_force=-1", "continuous_force '-1'"},
      {"h:1,continuous_force=2N", "continuous_force '2N'"},
      {"h:1,max_force=2", "continuous_force"},   // fine: 0.88 <= 2
      {"h:1,continuous_force=4", "continuous_force 4.000000 N is above max_force 3.300000 N (of the model)"},
      {"h:1,max_force=1,continuous_force=1.5", "is above max_force 1.000000 N (given)"},
  };
  for (const auto& [spec, message] : bad) {
    INFO(spec);
    if (std::string(spec) == "h:1,max_force=2") {
      CHECK_NOTHROW(parse_udp_spec(spec));
      continue;
    }
    CHECK_THROWS_WITH(parse_udp_spec(spec), Catch::Contains(std::string("udp device spec '") + spec + "'") &&
                                                Catch::Contains(message));
  }
  // The device refuses a configuration the parser never makes, naming the field.
  UdpPeer peer;
  ForceSafetyConfig s;
  s.continuous_force = 20.0;
  CHECK_THROWS_WITH(UdpDevice(lockstep(peer, s)), Catch::Contains("udp device 127.0.0.1:") &&
                                                     Catch::Contains("continuous_force"));
}
