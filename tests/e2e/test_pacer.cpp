// The real-time pacer (app/pacer.hpp) on an injected clock: no wall-clock thresholds. A tick
// whose work ends after start + (n + 1) T is an overrun, one that ends more than the stall
// timeout after the previous tick ended is a stall; an early tick sleeps to its deadline exactly. In a run, an
// artificially slow device read is counted and flagged in /devices, and a stall releases every
// device and stops the run.
#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <functional>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "app/pacer.hpp"
#include "app/run.hpp"
#include "graspsim/hw/scripted_finger.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/scripting/scenario.hpp"

using namespace graspsim;

namespace {

// Time moves only when work is simulated (advance) or the pacer sleeps (to its deadline).
class FakeClock final : public app::MonotonicClock {
 public:
  std::int64_t t = 1'000'000'000;   // ns: an arbitrary origin
  std::int64_t sleeps = 0;
  std::int64_t now_ns() override { return t; }
  void sleep_until_ns(std::int64_t deadline) override {
    ++sleeps;
    if (deadline > t) t = deadline;
  }
};

const std::string kLift = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/two_finger_lift.lua";
const std::string kTmp = GRASPSIM_TEST_TMP;

}  // namespace

TEST_CASE("Pacer: on-time ticks sleep to their deadlines, a slow one is one overrun", "[pacer]") {
  // T = 1/1000 s = 1,000,000 ns. Work of w < T per tick: the clock ends tick n exactly at
  // start + (n + 1) T (absolute deadlines: no drift). A tick of work 2.5 T ends 1.5 T late
  // (lateness 1.5 ms); with the schedule kept, the next ticks (work 0.2 T) catch up 0.8 T each
  // and are on time again. Swept over the slow tick's work: 1.01 T (just late: 0.01 T) to 20 T.
  for (const double slow : {1.01, 2.5, 20.0}) {
    FakeClock clock;
    app::Pacer pacer(clock, 1000, 1.0);
    pacer.start();
    const std::int64_t start = clock.t;
    std::int64_t late_ticks = 0;
    for (std::int64_t n = 0; n < 100; ++n) {
      clock.t += n == 50 ? static_cast<std::int64_t>(slow * 1e6) : 200'000;
      const app::TickPace p = pacer.end_tick(n);
      late_ticks += p.overrun;
      if (n == 50) {
        CHECK(p.overrun);
        CHECK(p.lateness == Approx((slow - 1.0) * 1e-3).margin(1e-12));
        CHECK_FALSE(p.stalled);
      }
      if (n < 50) CHECK(clock.t == start + (n + 1) * 1'000'000);
    }
    // After the slow tick, the overrun lasts until the lost time is made up at 0.8 T per tick:
    // ceil((slow - 1) / 0.8) ticks late in all (1 for 1.01, 2 for 2.5, 24 for 20).
    const auto expected = static_cast<std::int64_t>(std::ceil((slow - 1.0) / 0.8 - 1e-9));
    CHECK(pacer.overruns() == expected);
    CHECK(late_ticks == expected);
    CHECK(pacer.ticks() == 100);
    CHECK(pacer.worst_lateness() == Approx((slow - 1.0) * 1e-3).margin(1e-12));
    CHECK(clock.t == start + 100 * 1'000'000);   // back on schedule at the end
  }
}

TEST_CASE("Pacer: a gap between two ticks past the stall timeout is a stall", "[pacer]") {
  // The law: tick n stalls when its end follows tick n-1's end (tick 0: start()) by more than
  // the timeout; how late it is against the schedule does not matter. Timeout 20 ms at 1 kHz
  // (T = 1 ms), times in ns on the fake clock, exact.
  FakeClock clock;
  app::Pacer pacer(clock, 1000, 0.02);
  pacer.start();
  clock.t += 20'000'000;   // tick 0 ends 20 ms after start: gap 20 ms (not more), 19 ms late
  app::TickPace p = pacer.end_tick(0);
  CHECK(p.overrun);
  CHECK(p.gap == Approx(0.020).margin(1e-12));
  CHECK(p.lateness == Approx(0.019).margin(1e-12));
  CHECK_FALSE(p.stalled);
  clock.t += 3'000'000;    // tick 1: 21 ms late, but its forces follow tick 0's by 3 ms
  p = pacer.end_tick(1);
  CHECK(p.overrun);
  CHECK(p.lateness == Approx(0.021).margin(1e-12));
  CHECK_FALSE(p.stalled);
  clock.t += 20'000'001;   // tick 2: 1 ns more than the timeout after tick 1
  p = pacer.end_tick(2);
  CHECK(p.stalled);
  CHECK(pacer.worst_gap() == Approx(0.020000001).margin(1e-12));
  CHECK_THROWS_WITH(app::Pacer(clock, 0, 0.02), Catch::Contains("rate must be > 0"));
  CHECK_THROWS_WITH(app::Pacer(clock, 1000, 0.0), Catch::Contains("stall timeout"));
}

TEST_CASE("Pacer: a loop steadily slower than its rate lags past the lag limit", "[pacer]") {
  // Every tick's work takes w = s T with s > 1 (T = 1 ms, 1 kHz): tick n ends at
  // start + (n + 1) w, its gap is w and its lateness (n + 1)(w - T). Laws: it stalls at once if
  // w > 20 ms (the stall timeout); otherwise it lags at the first tick whose lateness passes
  // the 100 ms lag limit, n* = floor(100 ms / (w - T)) (integer ns, exact), and never before.
  // Swept over s: 1.05 (n* = 2000, past the 1000 ticks run: no lag), 2 (n* = 100), 19 (n* = 5),
  // 21 (a stall at tick 0).
  for (const double s : {1.05, 2.0, 19.0, 21.0}) {
    INFO("s = " << s);
    FakeClock clock;
    app::Pacer pacer(clock, 1000, 0.02, 0.1);
    pacer.start();
    const auto work = static_cast<std::int64_t>(std::llround(s * 1e6));
    std::int64_t first_stall = -1, first_lag = -1;
    for (std::int64_t n = 0; n < 1000; ++n) {
      clock.t += work;
      const app::TickPace p = pacer.end_tick(n);
      if (p.stalled && first_stall < 0) first_stall = n;
      if (p.lagging && first_lag < 0) first_lag = n;
      if (!p.overrun) FAIL("tick " << n << " on time");
    }
    CHECK(pacer.worst_gap() == Approx(static_cast<double>(work) * 1e-9).margin(1e-12));
    CHECK(first_stall == (work > 20'000'000 ? 0 : -1));
    const std::int64_t lag_tick = 100'000'000 / (work - 1'000'000);
    CHECK(first_lag == (lag_tick < 1000 ? lag_tick : -1));
  }
  CHECK_THROWS_WITH([] { FakeClock c; app::Pacer p(c, 1000, 0.02, 0.0); }(), Catch::Contains("lag limit"));
}

namespace {

// A scripted finger whose read of one tick takes `work` ns on the fake clock.
class SlowFinger final : public hw::Device {
 public:
  SlowFinger(std::unique_ptr<hw::Trajectory> t, FakeClock& clock, std::int64_t slow_tick, std::int64_t work,
             hw::Vec3& last)
      : t_(std::move(t)), clock_(clock), slow_tick_(slow_tick), work_(work), last_(last) {}
  std::function<void(std::int64_t)> on_tick;   // called at every read, if set
  hw::DeviceSample read(std::int64_t tick, double time) override {
    if (tick == slow_tick_) clock_.t += work_;
    if (on_tick) on_tick(tick);
    hw::DeviceSample s;
    s.position = t_->sample(time).position;
    return s;
  }
  hw::DeviceLimits limits() const override { return {10.0}; }
  std::string describe() const override { return "slow"; }

 protected:
  void output(const hw::Vec3& f) override { last_ = f; }

 private:
  std::unique_ptr<hw::Trajectory> t_;
  FakeClock& clock_;
  std::int64_t slow_tick_, work_;
  hw::Vec3& last_;
};

}  // namespace

TEST_CASE("A paced run counts the overrun of an artificially slow tick and records it", "[pacer][e2e]") {
  // Tick 4500 (in contact: 1.5 s) of the index device takes 2 T = 667 us on the fake clock; every
  // other tick takes none. Exactly that tick overruns (by T, 333 us); the next one ends at its
  // deadline (not after it), so 1 overrun in 12000, flagged at row 4500 of /devices/index.
  const auto scenario = scripting::Scenario::load(kLift);
  FakeClock clock;
  app::Pacer pacer(clock, 3000, app::kStallTimeout);
  std::vector<hw::Vec3> last(2, hw::Vec3::Ones());
  app::RunOptions o;
  o.out = kTmp + "/pacer_overrun.h5";
  o.pacing.pacer = &pacer;
  o.devices.record = {false, true};
  o.devices.make = [&](std::size_t f) -> std::unique_ptr<hw::Device> {
    return std::make_unique<SlowFinger>(scenario.make_trajectory(f), clock, f == 1 ? 4500 : -1, 666'666, last[f]);
  };
  const app::RunResult r = app::run_scenario(scenario, o);
  INFO(r.error);
  REQUIRE(r.error.empty());
  CHECK(r.overruns == 1);
  CHECK_THAT(r.pacing, Catch::StartsWith("1 of 12000 ticks overran"));
  const auto flags = recordings::read_dataset(o.out, "/devices/index/overrun").values;
  REQUIRE(flags.size() == 12000);
  for (std::size_t n = 0; n < flags.size(); ++n)
    if (flags[n] != (n == 4500 ? 1.0 : 0.0)) FAIL("overrun flag " << flags[n] << " at row " << n);
  CHECK(last[0] == hw::Vec3::Zero());
  CHECK(last[1] == hw::Vec3::Zero());
}

TEST_CASE("A paced run that stalls past the timeout releases every device and stops", "[pacer][e2e][safety]") {
  // Tick 4500 takes 30 ms against the 20 ms stall timeout (T = 0.33 ms): the run stops there
  // with an error naming the stall, and every device's last force is zero.
  const auto scenario = scripting::Scenario::load(kLift);
  FakeClock clock;
  app::Pacer pacer(clock, 3000, app::kStallTimeout);
  std::vector<hw::Vec3> last(2, hw::Vec3::Ones());
  app::RunOptions o;
  o.out = kTmp + "/pacer_stall.h5";
  o.pacing.pacer = &pacer;
  o.devices.make = [&](std::size_t f) -> std::unique_ptr<hw::Device> {
    return std::make_unique<SlowFinger>(scenario.make_trajectory(f), clock, f == 1 ? 4500 : -1, 30'000'000, last[f]);
  };
  const app::RunResult r = app::run_scenario(scenario, o);
  CHECK_THAT(r.error, Catch::Contains("the servo loop stalled: tick 4500's forces went out 30.000 ms after") &&
                          Catch::Contains("every device was released"));
  CHECK(r.servo_ticks == 4500);
  CHECK(last[0] == hw::Vec3::Zero());
  CHECK(last[1] == hw::Vec3::Zero());
}

TEST_CASE("A paced run sees Ctrl-C at the next tick and releases every device", "[pacer][e2e][safety]") {
  // Unpaced, the interrupt is polled every 3000 ticks (1 s simulated); paced (a hand on a real
  // device) at every tick: raised during tick 4500's read, the run stops after that tick, with
  // 4501 servo ticks done, and every device's last force is zero.
  const auto scenario = scripting::Scenario::load(kLift);
  FakeClock clock;
  app::Pacer pacer(clock, 3000, app::kStallTimeout);
  std::vector<hw::Vec3> last(2, hw::Vec3::Ones());
  std::atomic<bool> interrupt{false};
  app::RunOptions o;
  o.out = kTmp + "/pacer_interrupt.h5";
  o.pacing.pacer = &pacer;
  o.stop.interrupt = &interrupt;
  o.devices.make = [&](std::size_t f) -> std::unique_ptr<hw::Device> {
    auto d = std::make_unique<SlowFinger>(scenario.make_trajectory(f), clock, -1, 0, last[f]);
    if (f == 1) d->on_tick = [&](std::int64_t n) { if (n == 4500) interrupt.store(true); };
    return d;
  };
  const app::RunResult r = app::run_scenario(scenario, o);
  CHECK(r.interrupted);
  CHECK(r.servo_ticks == 4501);
  CHECK(last[0] == hw::Vec3::Zero());
  CHECK(last[1] == hw::Vec3::Zero());
}

TEST_CASE("A device that fails to open releases the ones already open", "[e2e][safety]") {
  // The index device's factory throws (a device that does not open): the thumb's device, built
  // first, gets zero force; the error names the failure.
  const auto scenario = scripting::Scenario::load(kLift);
  FakeClock clock;
  std::vector<hw::Vec3> last(2, hw::Vec3::Ones());
  app::RunOptions o;
  o.out = kTmp + "/device_open_fails.h5";
  o.devices.make = [&](std::size_t f) -> std::unique_ptr<hw::Device> {
    if (f == 1) throw std::runtime_error("phantom 'Right': HD_DEVICE_NOT_FOUND");
    return std::make_unique<SlowFinger>(scenario.make_trajectory(f), clock, -1, 0, last[f]);
  };
  const app::RunResult r = app::run_scenario(scenario, o);
  CHECK_THAT(r.error, Catch::Contains("HD_DEVICE_NOT_FOUND"));
  CHECK(last[0] == hw::Vec3::Zero());
}
