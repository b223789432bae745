// UdpLink and UdpDevice (hw/README.md, "UDP protocol"). The link's rules (newest sample by
// sequence number, holds, gaps, late and malformed datagrams, the timeout in graspsim's time)
// are tested on bytes alone; the device over loopback against an in-process fake server that
// answers in lockstep, so no test depends on timing.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <poll.h>
#include <string>

#include "graspsim/hw/udp_device.hpp"
#include "tests/hw/udp_peer.hpp"

using namespace graspsim::hw;
using graspsim::test::line_sample;
using graspsim::test::UdpPeer;

namespace {

void feed(UdpLink& link, const udp::Sample& s) {
  std::uint8_t b[udp::kSampleSize];
  link.accept(b, udp::encode(s, b));
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The link's tests see the clamp alone: the device's safety with the same peak, no thermal
// derating (C = P) and no ramp, so every force sent is the clamped request bit for bit.
UdpDeviceConfig lockstep_config(const UdpPeer& peer, double timeout_s, double max_force) {
  UdpDeviceConfig c{"127.0.0.1", peer.port(), 0, timeout_s, DeviceLimits{max_force}};
  c.lockstep = true;
  c.safety.peak_force = c.safety.continuous_force = max_force;
  c.safety.rise_time = 0.0;
  return c;
}

}  // namespace

// ---- UdpLink: the rules, without sockets ------------------------------------------------------

TEST_CASE("UdpLink keeps the newest sample by sequence number and counts gaps, late and holds",
          "[hw][udp]") {
  UdpLink link(1.0);
  CHECK(link.link_lost());   // no sample yet
  feed(link, line_sample(0));
  DeviceSample s = link.read(0.0);
  CHECK(!link.link_lost());
  CHECK(s.position == Vec3(0.0, 0.0, 0.5));
  // Three in one drain, out of order: 3 then 5 then 4. The newest (5) wins; 3 -> 5 skipped one
  // number (lost 1 at 0 -> 3 gives 2 more); 4 arrives after 5: late, dropped.
  feed(link, line_sample(3));
  feed(link, line_sample(5));
  feed(link, line_sample(4));
  s = link.read(0.001);
  CHECK(s.position == Vec3(5e-3, -10e-3, 0.5));
  CHECK(s.buttons == 1u);
  CHECK(link.newest().sequence == 5);
  // A duplicate of 5 and an old 1: both late; the read holds 5.
  feed(link, line_sample(5));
  feed(link, line_sample(1));
  s = link.read(0.002);
  CHECK(s.position == Vec3(5e-3, -10e-3, 0.5));
  const UdpCounters& c = link.counters();
  CHECK(c.received == 3);   // 0, 3, 5
  CHECK(c.lost == 3);       // 1, 2 (before 3) and 4 (before 5)
  CHECK(c.late == 3);       // 4, the second 5, 1
  CHECK(c.held == 1);
  CHECK(c.malformed == 0);
  CHECK(c.link_lost == 0);
}

TEST_CASE("UdpLink orders sequence numbers across the uint32 wrap", "[hw][udp]") {
  // Serial number arithmetic: 0 follows 0xFFFFFFFF, 0xFFFFFFFE precedes it.
  UdpLink link(1.0);
  feed(link, line_sample(0xFFFFFFFEu));
  feed(link, line_sample(0u));
  CHECK(link.newest().sequence == 0u);
  CHECK(link.counters().lost == 1);   // 0xFFFFFFFF
  feed(link, line_sample(0xFFFFFFFFu));
  CHECK(link.counters().late == 1);
  CHECK(link.newest().sequence == 0u);
}

TEST_CASE("UdpLink: malformed datagrams are counted and never used", "[hw][udp]") {
  UdpLink link(1.0);
  feed(link, line_sample(7));
  link.read(0.0);
  std::uint8_t b[udp::kSampleSize];
  udp::Sample nan_sample = line_sample(8);
  nan_sample.position[1] = std::numeric_limits<double>::quiet_NaN();
  udp::encode(nan_sample, b);
  link.accept(b, sizeof b);                   // a NaN
  udp::encode(line_sample(9), b);
  link.accept(b, sizeof b - 1);               // truncated
  b[4] = 1;
  link.accept(b, sizeof b);                   // version 1 (an old server)
  link.accept(nullptr, 0);                    // empty
  udp::encode(udp::Force{}, b);
  link.accept(b, udp::kForceSize);            // a force: not a sample
  link.count_malformed();                     // too large to read (UdpDevice's case)
  const DeviceSample s = link.read(0.001);
  CHECK(link.counters().malformed == 6);
  CHECK(link.counters().received == 1);
  CHECK(link.counters().held == 1);
  CHECK(link.newest().sequence == 7);
  CHECK(s.position == Vec3(7e-3, -14e-3, 0.5));
}

TEST_CASE("UdpLink: a sample declaring the other mode is never used and marks the link mismatched",
          "[hw][udp][mode]") {
  // Protocol v2: every sample declares the server's mode. The rule, both ways: a valid sample
  // whose mode is not the expected one is not used (not received, not newest, the read holds
  // the last good sample) and the link is mismatched from then on, naming the first offender.
  for (const udp::Mode expected : {udp::Mode::kStreaming, udp::Mode::kLockstep}) {
    const udp::Mode other = expected == udp::Mode::kLockstep ? udp::Mode::kStreaming : udp::Mode::kLockstep;
    INFO("expected " << udp::describe(expected));
    UdpLink link(1.0, expected);
    CHECK(link.expected_mode() == expected);
    udp::Sample good = line_sample(1);
    good.mode = expected;
    feed(link, good);
    link.read(0.0);
    CHECK(!link.mode_mismatch());
    udp::Sample bad = line_sample(2);
    bad.mode = other;
    feed(link, bad);
    udp::Sample bad2 = line_sample(3);
    bad2.mode = other;
    feed(link, bad2);
    CHECK(link.mode_mismatch());
    CHECK(link.mismatch_sequence() == 2);   // the first, not the last
    const DeviceSample s = link.read(0.001);
    CHECK(s.position == Vec3(1e-3, -2e-3, 0.5));   // sample 1 held, 2 and 3 never used
    CHECK(link.newest().sequence == 1);
    CHECK(link.counters().received == 1);
    CHECK(link.counters().held == 1);
    CHECK(link.counters().malformed == 0);   // valid datagrams: a mismatch, not garbage
    feed(link, good);                        // a later right sample does not clear it
    CHECK(link.mode_mismatch());
  }
  // The default is streaming: the safe assumption (a client that did not ask for lockstep).
  UdpLink plain(1.0);
  CHECK(plain.expected_mode() == udp::Mode::kStreaming);
}

TEST_CASE("UdpLink remembers why the last datagram was refused and its version", "[hw][udp][mode]") {
  UdpLink link(1.0);
  CHECK(link.last_refusal() == udp::DecodeStatus::kOk);
  std::uint8_t b[udp::kSampleSize];
  udp::encode(line_sample(0), b);
  b[4] = 1;   // what a version-1 server sends (its size differs too; the version is checked first)
  link.accept(b, 72);
  CHECK(link.last_refusal() == udp::DecodeStatus::kBadVersion);
  CHECK(link.last_refused_version() == 1);
  link.accept(reinterpret_cast<const std::uint8_t*>("hello, world"), 12);
  CHECK(link.last_refusal() == udp::DecodeStatus::kBadMagic);
  CHECK(link.last_refused_version() == 0);
  CHECK(!link.has_sample());
}

TEST_CASE("UdpLink: the link is lost exactly when no new sample came for longer than the timeout",
          "[hw][udp][timeout]") {
  // The law: with the last new sample seen at the read at time t0, the link is lost at the first
  // read whose time t satisfies t - t0 > timeout. At servo rate R, with t = n / R computed from
  // the tick as the run loop does, and timeout * R = k a whole number, n / R rounds to the same
  // double as the literal k / R = timeout (IEEE division is correctly rounded), so the read at
  // n = k is still alive and n = k + 1 is the first lost: k + 1 holds. Exact, so no tolerance.
  for (const int rate : {1000, 3000}) {
    for (const double timeout : {0.01, 0.05, 0.2}) {
      for (const std::int64_t start : {0, 4321}) {
        UdpLink link(timeout);
        feed(link, line_sample(1));
        link.read(static_cast<double>(start) / rate);
        const double t0 = static_cast<double>(start) / rate;
        std::int64_t first_lost = -1;
        for (std::int64_t n = 1; n <= 2 * static_cast<std::int64_t>(timeout * rate) + 10; ++n) {
          link.read(static_cast<double>(start + n) / rate);
          if (link.link_lost()) {
            first_lost = n;
            break;
          }
        }
        const std::int64_t k = std::llround(timeout * rate);
        INFO("rate " << rate << " Hz, timeout " << timeout << " s, t0 " << t0 << " s");
        // With start != 0 the difference of two rounded times may land one ulp either side of
        // the timeout; the law still decides at k or k + 1 and nowhere else.
        if (start == 0) {
          CHECK(first_lost == k + 1);
        } else {
          CHECK((first_lost == k + 1 || first_lost == k));
          const double dt_at = static_cast<double>(start + first_lost) / rate - t0;
          CHECK(dt_at > timeout);
          const double dt_before = static_cast<double>(start + first_lost - 1) / rate - t0;
          CHECK(!(dt_before > timeout));
        }
        CHECK(link.counters().held == static_cast<std::uint64_t>(first_lost));
        CHECK(link.counters().link_lost == 1);
        // A new sample revives the link at once.
        feed(link, line_sample(2));
        link.read(static_cast<double>(start + first_lost + 1) / rate);
        CHECK(!link.link_lost());
      }
    }
  }
}

// ---- UdpDevice on loopback ----------------------------------------------------------------------

TEST_CASE("UdpDevice on loopback: samples in, forces out, sequence numbers checked", "[hw][udp][loopback]") {
  UdpPeer peer;
  UdpDevice d(lockstep_config(peer, 0.05, 5.0));
  CHECK(d.describe() == "udp 127.0.0.1:" + std::to_string(peer.port()) + " (lockstep) (touch: 5 N peak, 5 N continuous)");
  CHECK(peer.receive_hello().sequence == 0);
  for (std::uint32_t n = 0; n < 200; ++n) {
    const udp::Sample sent = line_sample(n);
    peer.send(sent);
    const DeviceSample s = d.read(n, n / 3000.0);
    for (int i = 0; i < 3; ++i) {
      CHECK(same_bits(s.position[i], sent.position[i]));
      CHECK(same_bits(s.gimbal[i], sent.gimbal[i]));
    }
    CHECK(s.buttons == sent.buttons);
    CHECK(same_bits(d.newest().device_time, sent.device_time));
    // Every 50th force is far over the 5 N limit: what goes out is the clamped force.
    const Vec3 asked = n % 50 == 49 ? Vec3(300.0, -400.0, 0.0) : Vec3(0.01 * n, -0.5, 1.0 / 3.0);
    const Vec3 rendered = d.render(asked);
    const udp::Force f = peer.receive_force();
    CHECK(f.sequence == n + 1);   // the hello was datagram 0
    CHECK(f.answers == n);
    for (int i = 0; i < 3; ++i) CHECK(same_bits(f.force[i], rendered[i]));
    CHECK(Vec3(f.force[0], f.force[1], f.force[2]).norm() <= 5.0);
    if (n % 50 == 49) CHECK(rendered.norm() == Approx(5.0).epsilon(1e-15));
  }
  const UdpCounters& c = d.counters();
  CHECK(c.received == 200);
  CHECK(c.lost == 0);
  CHECK(c.late == 0);
  CHECK(c.malformed == 0);
  CHECK(c.held == 0);
  CHECK(d.datagrams_sent() == 201);
  d.release();
  const udp::Force last = peer.receive_force();
  CHECK(last.force[0] == 0.0);
  CHECK(last.force[1] == 0.0);
  CHECK(last.force[2] == 0.0);
}

TEST_CASE("UdpDevice on loopback: lost samples are held and counted, and the force drops to zero "
          "after the timeout", "[hw][udp][loopback][timeout]") {
  // The server loses samples 20 to 20 + gap - 1. In lockstep it still answers every force, with
  // a repeat of sample 19 (a duplicate: late, dropped), so the device holds 19. At 3000 Hz with
  // a 0.05 s timeout (150 ticks, see the UdpLink timeout law), the reads at ticks 20..169 hold
  // and are alive, the read at tick 170 (151 holds) is lost: from its render on, the force the
  // server receives is zero. Sample 20 + gap revives the link and the force.
  for (const int gap : {100, 200, 400}) {
    UdpPeer peer;
    UdpDevice d(lockstep_config(peer, 0.05, 5.0));
    peer.receive_hello();
    const Vec3 push(0.0, 0.0, 1.0);
    int zero_from = -1;
    const int ticks = 20 + gap + 10;
    for (int n = 0; n < ticks; ++n) {
      const bool dropped = n >= 20 && n < 20 + gap;
      // Tick n reads sample n, or a repeat of 19 while dropped; after the gap, sample n.
      peer.send(line_sample(dropped ? 19u : static_cast<std::uint32_t>(n)));
      const DeviceSample s = d.read(n, n / 3000.0);
      CHECK(s.position[0] == line_sample(dropped ? 19u : static_cast<std::uint32_t>(n)).position[0]);
      d.render(push);
      const udp::Force f = peer.receive_force();
      CHECK(f.answers == (dropped ? 19u : static_cast<std::uint32_t>(n)));
      const bool zero = f.force[2] == 0.0;
      if (zero && zero_from < 0) zero_from = n;
      if (!zero && zero_from >= 0) CHECK(n >= 20 + gap);   // nonzero again only after the gap
      CHECK(zero == d.link_lost());
    }
    INFO("gap " << gap);
    const bool times_out = gap > 150;
    CHECK(zero_from == (times_out ? 170 : -1));
    const UdpCounters& c = d.counters();
    CHECK(c.held == static_cast<std::uint64_t>(gap));
    CHECK(c.late == static_cast<std::uint64_t>(gap));
    CHECK(c.lost == static_cast<std::uint64_t>(gap));   // 19 -> 20 + gap skips gap numbers
    CHECK(c.received == static_cast<std::uint64_t>(ticks - gap));
    CHECK(c.link_lost == (times_out ? 1u : 0u));
    CHECK(!d.link_lost());
  }
}

TEST_CASE("UdpDevice on loopback: malformed datagrams are counted and dropped", "[hw][udp][loopback]") {
  UdpPeer peer;
  UdpDevice d(lockstep_config(peer, 1.0, 5.0));
  peer.receive_hello();
  peer.send(line_sample(0));
  d.read(0, 0.0);
  // Each force is answered with garbage: random bytes, a truncated sample, a NaN sample, a
  // force, and a datagram larger than any message (read with MSG_TRUNC: counted, not parsed).
  std::uint8_t big[300] = {};
  std::uint8_t b[udp::kSampleSize];
  udp::Sample nan = line_sample(1);
  nan.device_time = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 5; ++k) {
    d.render(Vec3(0.0, 0.0, 1.0));
    peer.receive_force();
    switch (k) {
      case 0: peer.send("hello, world", 12); break;
      case 1: udp::encode(line_sample(1), b); peer.send(b, udp::kSampleSize - 8); break;
      case 2: udp::encode(nan, b); peer.send(b, udp::kSampleSize); break;
      case 3: udp::encode(udp::Force{}, b); peer.send(b, udp::kForceSize); break;
      case 4: udp::encode(line_sample(1), big); peer.send(big, sizeof big); break;
    }
    const DeviceSample s = d.read(k + 1, (k + 1) / 3000.0);
    CHECK(s.position == Vec3(0.0, 0.0, 0.5));
  }
  CHECK(d.counters().malformed == 5);
  CHECK(d.counters().held == 5);
  CHECK(d.counters().received == 1);
  CHECK(d.newest().sequence == 0);
}

TEST_CASE("UdpDevice: read never waits outside lockstep, and the first sample is waited for at start-up",
          "[hw][udp][loopback]") {
  UdpPeer peer(udp::Mode::kStreaming);   // not lockstep: the server must stream
  UdpDeviceConfig c{"127.0.0.1", peer.port(), 0, 0.05, DeviceLimits{5.0}};
  c.safety.peak_force = c.safety.continuous_force = 5.0;   // the clamp alone (no derating, no ramp)
  c.safety.rise_time = 0.0;
  UdpDevice d(c);
  // Nothing sent yet: the read returns at once, with no sample, counted as a hold; link lost,
  // so a force renders zero.
  const DeviceSample none = d.read(0, 0.0);
  CHECK(none.position == Vec3::Zero());
  CHECK(d.counters().held == 1);
  CHECK(d.link_lost());
  d.render(Vec3(1.0, 0.0, 0.0));
  CHECK(d.last_force() == Vec3::Zero());
  CHECK(peer.receive_hello().sequence == 0);
  CHECK(peer.receive_force().force[0] == 0.0);
  peer.send(line_sample(3));
  REQUIRE(d.wait_for_first_sample(10.0));   // returns as soon as it is there
  CHECK(d.read(1, 1.0 / 3000.0).position == line_sample(3).position[0] * Vec3::UnitX() +
                                              line_sample(3).position[1] * Vec3::UnitY() + 0.5 * Vec3::UnitZ());
  CHECK(!d.link_lost());
  CHECK(d.render(Vec3(1.0, 0.0, 0.0)) == Vec3(1.0, 0.0, 0.0));
  CHECK(d.last_force() == Vec3(1.0, 0.0, 0.0));
}

TEST_CASE("UdpDevice: a server that does not answer is a clear error", "[hw][udp][loopback]") {
  UdpPeer silent;
  UdpDeviceConfig c{"127.0.0.1", silent.port(), 0, 0.05, DeviceLimits{}};
  c.handshake_s = 0.2;
  CHECK_THROWS_WITH(make_udp_device(c), Catch::Contains("udp device 127.0.0.1:" + std::to_string(silent.port())) &&
                                            Catch::Contains("no sample within") &&
                                            Catch::Contains("device_server"));
  c.lockstep = true;
  c.answer_wait_s = 0.2;
  UdpDevice d(c);
  CHECK_THROWS_WITH(d.read(0, 0.0), Catch::Contains("no answer to datagram 0") && Catch::Contains("lockstep"));
  // A local port already in use: the error names it.
  UdpDeviceConfig taken{"127.0.0.1", silent.port(), silent.port(), 0.05, DeviceLimits{}};
  CHECK_THROWS_WITH(UdpDevice(taken), Catch::Contains("local UDP port " + std::to_string(silent.port())));
  UdpDeviceConfig no_port{"127.0.0.1", 0, 0, 0.05, DeviceLimits{}};
  CHECK_THROWS_WITH(UdpDevice(no_port), Catch::Contains("port must be 1 to 65535"));
  UdpDeviceConfig bad_timeout{"127.0.0.1", silent.port(), 0, 0.0, DeviceLimits{}};
  CHECK_THROWS_WITH(UdpDevice(bad_timeout), Catch::Contains("timeout_s must be a positive"));
}

// ---- Protocol v2: the server's declared mode must match the spec's ---------------------------

namespace {

// The device's config for a spec with or without `,lockstep`, against the peer.
UdpDeviceConfig spec_config(const UdpPeer& peer, bool lockstep) {
  UdpDeviceConfig c = lockstep_config(peer, 1.0, 5.0);
  c.lockstep = lockstep;
  c.handshake_s = 5.0;   // guards, not thresholds: the peer's answer is queued before the wait
  c.answer_wait_s = 5.0;
  return c;
}

// Reads until the datagram the peer just sent has been taken in (a new sample, or a mismatch,
// which throws). In lockstep read() waits by itself; a streaming read never waits, so retry it
// with a 1 ms pause, at most 10000 times: a guard against a hung test, not a timing threshold.
DeviceSample read_arrived(UdpDevice& d, std::int64_t tick, double time) {
  for (int i = 0;; ++i) {
    const DeviceSample s = d.read(tick, time);
    if (d.new_samples() > 0 || d.config().lockstep || i == 10000) return s;
    ::poll(nullptr, 0, 1);
  }
}

}  // namespace

TEST_CASE("UdpDevice: a lockstep spec against a streaming server is refused at start-up", "[hw][udp][mode]") {
  // The safety case: `,lockstep` (an unpaced, unprotected run) against a server that declares it
  // streams, e.g. one driving a real Phantom. start_up() (make_udp_device's handshake) throws
  // telling the user to drop ',lockstep', before any force is sent.
  UdpPeer streaming(udp::Mode::kStreaming);
  UdpDevice d(spec_config(streaming, true));
  CHECK(streaming.receive_hello().sequence == 0);
  streaming.send(line_sample(0));
  const std::string where = "127.0.0.1:" + std::to_string(streaming.port());
  CHECK_THROWS_WITH(d.start_up(), Catch::Contains("udp device " + where + ": the server at " + where +
                                                  " streams samples (a real device?): a lockstep run would not be "
                                                  "paced; drop ',lockstep'") &&
                                      Catch::Contains("sample 0 declared streaming"));
  CHECK(!d.has_sample());
  CHECK(d.datagrams_sent() == 1);   // the hello alone: no force ever went out
  // The same server against the right spec starts.
  UdpPeer streaming2(udp::Mode::kStreaming);
  UdpDevice ok(spec_config(streaming2, false));
  streaming2.receive_hello();
  streaming2.send(line_sample(0));
  CHECK_NOTHROW(ok.start_up());
  CHECK(ok.has_sample());
}

TEST_CASE("UdpDevice: a streaming spec against a lockstep server is refused at start-up", "[hw][udp][mode]") {
  // Chosen: an error, not a warning (hw/README.md): a lockstep peer sends one sample per
  // datagram, so a paced client would get them late and by scheduling luck, a silently
  // timing-dependent run; the fix is one word.
  UdpPeer lockstep(udp::Mode::kLockstep);
  UdpDevice d(spec_config(lockstep, false));
  lockstep.receive_hello();
  lockstep.send(line_sample(0));
  CHECK_THROWS_WITH(d.start_up(), Catch::Contains("is a lockstep peer") && Catch::Contains("add ',lockstep'") &&
                                      Catch::Contains("sample 0 declared lockstep"));
  UdpPeer lockstep2(udp::Mode::kLockstep);
  UdpDevice ok(spec_config(lockstep2, true));
  lockstep2.receive_hello();
  lockstep2.send(line_sample(0));
  CHECK_NOTHROW(ok.start_up());
  CHECK(ok.has_sample());
}

TEST_CASE("UdpDevice: a server that changes its declared mode mid-run stops the run", "[hw][udp][mode]") {
  // Every sample must declare the spec's mode, not just the first: the first that does not makes
  // read() throw (the run's error, after which the run releases every device), its position
  // never used. Both ways, after a sweep of good ticks.
  for (const bool lockstep : {true, false}) {
    for (const std::uint32_t good_ticks : {1u, 10u, 100u}) {
      INFO((lockstep ? "lockstep" : "streaming") << " spec, " << good_ticks << " good ticks");
      const udp::Mode mode = lockstep ? udp::Mode::kLockstep : udp::Mode::kStreaming;
      UdpPeer peer(mode);
      UdpDevice d(spec_config(peer, lockstep));
      peer.receive_hello();
      peer.send(line_sample(0));
      d.start_up();
      for (std::uint32_t n = 0; n < good_ticks; ++n) {
        read_arrived(d, n, n / 1000.0);
        d.render(Vec3(0.0, 0.0, 1.0));
        peer.receive_force();
        peer.send(line_sample(n + 1));
      }
      // The answer to the last force: a sample of the other mode, sent as raw bytes.
      read_arrived(d, good_ticks, good_ticks / 1000.0);
      REQUIRE(d.newest().sequence == good_ticks);
      d.render(Vec3(0.0, 0.0, 1.0));
      peer.receive_force();
      udp::Sample liar = line_sample(good_ticks + 1);
      liar.mode = lockstep ? udp::Mode::kStreaming : udp::Mode::kLockstep;
      std::uint8_t b[udp::kSampleSize];
      peer.send(b, udp::encode(liar, b));
      CHECK_THROWS_WITH(read_arrived(d, good_ticks + 1, (good_ticks + 1) / 1000.0),
                        Catch::Contains(lockstep ? "drop ',lockstep'" : "add ',lockstep'") &&
                            Catch::Contains("sample " + std::to_string(good_ticks + 1) + " declared"));
      CHECK(d.newest().sequence == good_ticks);   // the liar's sample was never used
      // The run then releases the device: a zero force goes out.
      d.release();
      const udp::Force last = peer.receive_force();
      CHECK(last.force[0] == 0.0);
      CHECK(last.force[1] == 0.0);
      CHECK(last.force[2] == 0.0);
      // And every later read throws too: the link stays mismatched.
      CHECK_THROWS(d.read(good_ticks + 2, (good_ticks + 2) / 1000.0));
    }
  }
}

TEST_CASE("UdpDevice: a version 1 server is refused at start-up naming both versions", "[hw][udp][mode]") {
  for (const bool lockstep : {true, false}) {
    UdpPeer old;
    UdpDeviceConfig c = spec_config(old, lockstep);
    c.handshake_s = 0.3;   // streaming: waits the whole handshake (the v1 sample is refused)
    UdpDevice d(c);
    old.receive_hello();
    std::uint8_t b[udp::kSampleSize];
    udp::encode(line_sample(0), b);
    b[4] = 1;
    old.send(b, 72);   // a v1 sample: version 1, 72 bytes
    CHECK_THROWS_WITH(d.start_up(), Catch::Contains("protocol version 1, but this graspsim speaks version 2"));
  }
}

TEST_CASE("parse_udp_spec: HOST:PORT with options, and clear errors", "[hw][udp][spec]") {
  UdpDeviceConfig c = parse_udp_spec("127.0.0.1:7001");
  CHECK(c.host == "127.0.0.1");
  CHECK(c.port == 7001);
  CHECK(c.local_port == 0);
  CHECK(c.timeout_s == UdpDeviceConfig{}.timeout_s);
  CHECK(!c.lockstep);
  c = parse_udp_spec("udp:lab-pc.local:65535,timeout=0.2,local_port=7002,lockstep");
  CHECK(c.host == "lab-pc.local");
  CHECK(c.port == 65535);
  CHECK(c.timeout_s == 0.2);
  CHECK(c.local_port == 7002);
  CHECK(c.lockstep);
  const std::pair<const char*, const char*> bad[] = {
      {"127.0.0.1", "no ':PORT'"},
      {":7001", "no host"},
      {"h:", "port '' is not a number"},
      {"h:0", "port '0' is not a number from 1 to 65535"},
      {"h:65536", "port '65536'"},
      {"h:70x", "port '70x'"},
      {"h:-1", "port '-1'"},
      {"h:99999999999999", "port '99999999999999'"},
      {"h:1,timeout=0", "timeout '0'"},
      {"h:1,timeout=nan", "timeout 'nan'"},
      {"h:1,timeout=1s", "timeout '1s'"},
      {"h:1,timeout=", "timeout ''"},
      {"h:1,local_port=x", "local_port 'x'"},
      {"h:1,speed=3", "unknown option 'speed=3'"},
      {"h:1,", "unknown option ''"},
      {"h:1,lockstep=1", "unknown option 'lockstep=1'"},
  };
  for (const auto& [spec, message] : bad) {
    INFO(spec);
    CHECK_THROWS_AS(parse_udp_spec(spec), std::invalid_argument);
    CHECK_THROWS_WITH(parse_udp_spec(spec), Catch::Contains(std::string("udp device spec '") + spec + "'") &&
                                                Catch::Contains(message) && Catch::Contains("HOST:PORT"));
  }
}
