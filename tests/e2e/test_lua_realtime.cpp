// Lua off the real-time thread (app/script_thread.hpp): in a paced run Lua
// trajectories are sampled ahead on a script thread into rings, expectations are checked after
// the loop, and the loop's thread may not enter Lua (the sandbox's thread guard). Paced runs use
// a fake clock (as tests/e2e/test_pacer.cpp): no wall-clock thresholds. A fake clock lets the loop
// outrun any thread, so the e2e runs set RunSeams::wait_for_script (the loop waits for a sample
// the script thread can still compute); a dry ring is tested on its own, with a script thread
// held at a gate.
#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "app/pacer.hpp"
#include "app/run.hpp"
#include "app/script_thread.hpp"
#include "graspsim/recordings/trace_compare.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/scripting/scenario.hpp"

using namespace graspsim;

namespace {

const std::string kTmp = GRASPSIM_TEST_TMP;

class FakeClock final : public app::MonotonicClock {
 public:
  std::int64_t t = 1'000'000'000;   // ns
  std::int64_t now_ns() override { return t; }
  void sleep_until_ns(std::int64_t deadline) override {
    if (deadline > t) t = deadline;
  }
};

std::string write_scenario(const std::string& name, const std::string& text) {
  const std::string path = kTmp + "/" + name + ".lua";
  std::ofstream(path) << text;
  return path;
}

// A finger pushes a box along the floor, moved by a Lua function of time only (with a pitch), so
// that the samples drive real contact; one expectation mid-run and one at the end.
const char* kPush = R"(
return {
  duration = 1.0,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  floor = { material = { mu = 0.5, stiffness = 100, damping = 1 } },
  objects = { { name = "box", size = { 0.04, 0.04, 0.04 }, mass = 0.4, position = { 0, 0, 0.01 } } },
  fingers = {
    { name = "pusher", stiffness = 400, damping = 4, max_force = 10,
      trajectory = function(t)
        return -0.05 + 0.1 * t + 0.002 * math.sin(40 * t), 0.001, 0.01, 0.3 * t
      end },
  },
  expect = {
    { what = "the finger is in contact by 0.6 s", at = 0.6,
      check = function(sim) return sim.fingers.pusher.touching == "box", sim.fingers.pusher.touching end },
    { what = "the box moved along x",
      check = function(sim)
        local dx = sim.objects.box.position[1] - sim.initial.objects.box.position[1]
        return dx > 0.01, string.format("%.17g", dx)
      end },
  },
}
)";

// A free finger far from a falling box whose height is the view's clock: z = 1 + sim.time. The
// sample for tick k thus shows which view it was computed with.
const char* kViewClock = R"(
return {
  duration = 0.2,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  objects = { { name = "box", size = { 0.04, 0.04, 0.04 }, mass = 0.1, position = { 0, 0, 1 } } },
  fingers = { { name = "probe", trajectory = function(t, sim) return 1, 0, 1 + sim.time end } },
}
)";

struct PacedRun {
  app::RunResult result;
  std::int64_t forbidden_uses = 0;
};

// Runs `scenario` paced on a fake clock, its fingers scripted (the run loop's own ScriptedFinger),
// the loop's thread forbidden to enter Lua.
PacedRun run_paced(const scripting::Scenario& scenario, const std::string& out) {
  FakeClock clock;
  app::Pacer pacer(clock, scenario.model().rates.servo, app::kStallTimeout);
  app::RunOptions o;
  o.out = kTmp + "/" + out + ".h5";
  o.pacing.pacer = &pacer;
  app::RunSeams seams;
  seams.wait_for_script = true;
  PacedRun r;
  r.result = app::run_scenario(scenario, o, seams);
  r.forbidden_uses = scenario.lua_uses_on_forbidden_thread();
  return r;
}

std::vector<double> hips(const std::string& trace, const std::string& finger) {
  return recordings::read_dataset(trace, "/servo/fingers/" + finger + "/hip").values;
}

}  // namespace

TEST_CASE("The thread guard refuses Lua on a forbidden thread and counts it", "[lua_realtime][safety]") {
  // The guard is what the paced runs below rely on: a call from the forbidden thread throws
  // before touching the state, and is counted; another thread, or the guard lifted, runs.
  const auto path = write_scenario("guard", kPush);
  const auto scenario = scripting::Scenario::load(path);
  auto trajectory = scenario.make_trajectory(0);
  scenario.forbid_lua_on(std::this_thread::get_id());
  CHECK_THROWS_WITH(trajectory->sample(0.5), Catch::Contains("Lua was called on the real-time loop thread"));
  CHECK(scenario.lua_uses_on_forbidden_thread() == 1);
  double x = 0.0;
  std::thread other([&] { x = trajectory->sample(0.5).position.x(); });
  other.join();
  CHECK(x == Approx(0.002 * std::sin(20.0)).margin(1e-15));   // -0.05 + 0.05 + 0.002 sin(40 * 0.5)
  scenario.forbid_lua_on(std::thread::id{});
  CHECK(trajectory->sample(0.5).position.x() == x);
  CHECK(scenario.lua_uses_on_forbidden_thread() == 1);
}

TEST_CASE("A paced run takes every Lua sample from the script thread: the trace is the unpaced one",
          "[lua_realtime][pacer][e2e]") {
  // With time-only trajectories the script thread computes exactly the calls an unpaced run makes
  // (ticks 0, 1, 2, ... at t = k / rate_servo), so the engine gets the same inputs: every dataset
  // of the paced trace equals the unpaced one bit for bit, and each recorded HIP equals the
  // function evaluated directly (in another Lua state) at its tick. The loop's thread never
  // entered Lua (the guard would have stopped the run with an error and counted it).
  const auto path = write_scenario("push", kPush);
  const auto paced_scenario = scripting::Scenario::load(path);
  const PacedRun paced = run_paced(paced_scenario, "lua_rt_paced");
  INFO(paced.result.error);
  REQUIRE(paced.result.error.empty());
  CHECK(paced.forbidden_uses == 0);
  CHECK(paced.result.script_holds == 0);
  CHECK_THAT(paced.result.pacing, Catch::Contains("Lua on a script thread: 0 samples held"));

  const auto unpaced_scenario = scripting::Scenario::load(path);
  app::RunOptions o;
  o.out = kTmp + "/lua_rt_unpaced.h5";
  const app::RunResult unpaced = app::run_scenario(unpaced_scenario, o);
  REQUIRE(unpaced.error.empty());
  REQUIRE(paced.result.expectations.size() == 2);
  for (std::size_t i = 0; i < 2; ++i) {
    INFO(unpaced.expectations[i].what << ": " << unpaced.expectations[i].detail);
    CHECK(unpaced.expectations[i].passed);
    CHECK(paced.result.expectations[i].passed);
    CHECK(paced.result.expectations[i].detail == unpaced.expectations[i].detail);
  }
  recordings::CompareOptions bitwise;
  bitwise.bitwise = true;
  const auto diff = recordings::compare_traces(o.out, kTmp + "/lua_rt_paced.h5", bitwise);
  CHECK(diff.differing_datasets() == 0);

  const auto direct_scenario = scripting::Scenario::load(path);
  auto direct = direct_scenario.make_trajectory(0);
  const auto hip = hips(kTmp + "/lua_rt_paced.h5", "pusher");
  const auto gimbal = recordings::read_dataset(kTmp + "/lua_rt_paced.h5", "/servo/fingers/pusher/gimbal").values;
  REQUIRE(hip.size() == 3 * 3000);
  for (std::int64_t k = 0; k < 3000; ++k) {
    const hw::TrajectorySample s = direct->sample(static_cast<double>(k) / 3000);
    for (int i = 0; i < 3; ++i)
      if (hip[3 * k + i] != s.position[i] || gimbal[3 * k + i] != s.gimbal[i])
        FAIL("tick " << k << " component " << i << ": recorded " << hip[3 * k + i] << ", direct " << s.position[i]);
  }
}

TEST_CASE("A paced run gives a view-reading trajectory the view one physics period later", "[lua_realtime][pacer][e2e]") {
  // The law (script_thread.hpp): unpaced, the sample for servo tick k is computed with the view
  // as the end of tick k - 1 left it; paced, as the end of tick k - D - 1 left it (D = 60 servo
  // ticks per physics period at 3000 / 50 Hz). The view changes after physics ticks p = 0, 60,
  // 120, ... and then reads time (p + 1) / 3000; before the first one it is the initial view, time
  // 0. So the probe's z = 1 + view time is, at tick k with j = k - 1 (unpaced) or k - 61 (paced):
  // 1 + (60 floor(j / 60) + 1) / 3000 for j >= 0, else 1. Exact: the same double operations.
  const auto path = write_scenario("view_clock", kViewClock);
  const auto expected_z = [](std::int64_t j) {
    if (j < 0) return 1.0;
    return 1.0 + static_cast<double>(60 * (j / 60) + 1) / 3000;
  };
  const auto unpaced_scenario = scripting::Scenario::load(path);
  app::RunOptions o;
  o.out = kTmp + "/lua_rt_view_unpaced.h5";
  REQUIRE(app::run_scenario(unpaced_scenario, o).error.empty());
  const auto paced_scenario = scripting::Scenario::load(path);
  const PacedRun paced = run_paced(paced_scenario, "lua_rt_view_paced");
  INFO(paced.result.error);
  REQUIRE(paced.result.error.empty());
  CHECK(paced.forbidden_uses == 0);
  CHECK_THAT(paced.result.pacing, Catch::Contains("view one physics period later than unpaced (20.0 ms)"));
  const auto unpaced_z = hips(o.out, "probe");
  const auto paced_z = hips(kTmp + "/lua_rt_view_paced.h5", "probe");
  REQUIRE(unpaced_z.size() == 3 * 600);
  REQUIRE(paced_z.size() == 3 * 600);
  for (std::int64_t k = 0; k < 600; ++k) {
    if (unpaced_z[3 * k + 2] != expected_z(k - 1)) FAIL("unpaced tick " << k << ": z " << unpaced_z[3 * k + 2]);
    if (paced_z[3 * k + 2] != expected_z(k - 61)) FAIL("paced tick " << k << ": z " << paced_z[3 * k + 2]);
  }
}

TEST_CASE("A script error in a paced run stops it at the tick it was due with the script's message",
          "[lua_realtime][pacer][e2e]") {
  // The script thread computes ahead and fails at t = 0.05 s (tick 150); the loop must not stop
  // earlier (samples before it are good) nor later: it stops when it asks for tick 150, as an
  // unpaced run does, with the same file:line message, and every device is released.
  const auto path = write_scenario("fails", R"(
return {
  duration = 0.2,
  objects = { { name = "box", size = { 0.04, 0.04, 0.04 }, mass = 0.1, position = { 0, 0, 1 } } },
  fingers = { { name = "probe", trajectory = function(t)
    if t >= 0.05 then error("boom") end
    return 1, 0, 0
  end } },
}
)");
  const auto unpaced_scenario = scripting::Scenario::load(path);
  app::RunOptions o;
  o.out = kTmp + "/lua_rt_fails_unpaced.h5";
  const app::RunResult unpaced = app::run_scenario(unpaced_scenario, o);
  const auto paced_scenario = scripting::Scenario::load(path);
  const PacedRun paced = run_paced(paced_scenario, "lua_rt_fails_paced");
  CHECK_THAT(unpaced.error, Catch::Contains("fails.lua:6: boom"));
  CHECK(paced.result.error == unpaced.error);
  CHECK(unpaced.servo_ticks == 150);
  CHECK(paced.result.servo_ticks == 150);
  CHECK(paced.forbidden_uses == 0);
}

namespace {

// A trajectory (no Lua needed to test the ring) that gives x = tick and blocks at tick `gate_at`
// until the gate opens: the script thread is then held there for sure.
class GatedTrajectory final : public hw::Trajectory {
 public:
  GatedTrajectory(std::int64_t gate_at, std::atomic<bool>& open) : gate_at_(gate_at), open_(open) {}
  hw::TrajectorySample sample(double t) override {
    const auto k = static_cast<std::int64_t>(std::llround(t * 3000));
    if (k >= gate_at_)
      while (!open_.load()) std::this_thread::yield();
    hw::TrajectorySample s;
    s.position.x() = static_cast<double>(k);
    return s;
  }

 private:
  std::int64_t gate_at_;
  std::atomic<bool>& open_;
};

}  // namespace

TEST_CASE("A ring that runs dry holds the last sample and counts every held tick", "[lua_realtime]") {
  // Look-ahead L = max(2 D, 20 ms x rate) = 120 ticks at 3000 / 50 Hz. start() returns when the
  // ring holds ticks 0 .. L - 1; the script thread is then held computing tick L. Ticks 0 .. L - 1
  // come out as computed; every later tick asked (L .. L + 9) finds the ring dry and holds tick
  // L - 1's sample: 10 holds, swept against how many ticks past the gate are asked (1, 10, 50).
  const auto scenario = scripting::Scenario::load(write_scenario("dry", kViewClock));
  REQUIRE(app::lookahead_ticks(3000, 60) == 120);
  REQUIRE(app::lookahead_ticks(3000, 1) == 60);   // 20 ms at 3 kHz
  for (const std::int64_t past : {1, 10, 50}) {
    std::atomic<bool> open{false};
    app::ScriptThreadOptions so;
    so.rate_servo = 3000;
    so.physics_divisor = 60;
    so.end_tick = 600;
    app::ScriptThread script(scenario, so);
    auto t = script.wrap(std::make_unique<GatedTrajectory>(120, open));
    // Opens the gate on every way out, before ~ScriptThread joins: a failed REQUIRE must fail
    // the test, not leave the script thread held and the join hanging.
    struct OpenOnExit {
      std::atomic<bool>& gate;
      ~OpenOnExit() { gate.store(true); }
    } open_on_exit{open};
    script.start();
    for (std::int64_t k = 0; k < 120; ++k)
      if (t->sample(static_cast<double>(k) / 3000).position.x() != static_cast<double>(k)) FAIL("tick " << k);
    for (std::int64_t k = 120; k < 120 + past; ++k) CHECK(t->sample(static_cast<double>(k) / 3000).position.x() == 119.0);
    CHECK(script.holds() == past);
    CHECK(script.off_grid() == 0);
    open.store(true);
    script.stop();
    CHECK_THAT(script.summary(), Catch::StartsWith("Lua on a script thread: " + std::to_string(past) + " samples held"));
  }
}

TEST_CASE("A request off the servo ticks gets the tick before it and is counted apart", "[lua_realtime]") {
  // Tick instants within 1 ns (another rounding of the same instant, e.g. j / 1000 at 3 kHz) are
  // the tick's sample; an instant between two ticks gets the script's sample of the tick before
  // (a zero-order hold of the servo-rate script; here x = tick number), counted as off the
  // grid, not as dry.
  const auto scenario = scripting::Scenario::load(write_scenario("grid", kViewClock));
  std::atomic<bool> open{true};
  app::ScriptThreadOptions so;
  so.end_tick = 600;
  app::ScriptThread script(scenario, so);
  auto t = script.wrap(std::make_unique<GatedTrajectory>(1 << 30, open));
  script.start();
  SECTION("in order") {
    CHECK(t->sample(0.0).position.x() == 0.0);
    CHECK(t->sample(0.001).position.x() == 3.0);          // 3 / 3000 computed as 1 / 1000
    CHECK(t->sample(1.0 / 6000 + 0.001).position.x() == 3.0);   // between ticks 3 and 4: held
    CHECK(t->sample(4.0 / 3000).position.x() == 4.0);
    CHECK(script.off_grid() == 1);
    CHECK(t->sample(5.5 / 3000).position.x() == 5.0);   // between ticks 5 and 6: tick 5's, ahead of `last`
    CHECK(script.off_grid() == 2);
  }
  SECTION("the first request between ticks") {
    // A device at its own rate under a servo rate that is no multiple of it (sim-phantom at
    // 1 kHz under 1500 Hz) asks first between ticks: tick 1's sample for 1.5 ticks, never the
    // zero sample nobody computed.
    CHECK(t->sample(1.5 / 3000).position.x() == 1.0);
    CHECK(script.off_grid() == 1);
  }
  CHECK(script.holds() == 0);
}
