// Devices on the command line (README.md, "Devices"): --device specs and their errors, a
// finger replayed from another trace, a mapped device session recorded in /devices/<finger> and
// replayed bit for bit, and every device released (zero force) at the end, on error and on
// interrupt.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "app/devices.hpp"
#include "app/replay.hpp"
#include "app/run.hpp"
#include "graspsim/hw/mapped_device.hpp"
#include "graspsim/hw/scripted_finger.hpp"
#include "graspsim/recordings/trace_compare.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "tests/support/shell.hpp"
#include "tests/support/library.hpp"

using namespace graspsim;

namespace {

const std::string kSource = GRASPSIM_SOURCE_DIR;
const std::string kLift = kSource + "/scenarios/two_finger_lift.lua";
const std::string kTmp = GRASPSIM_TEST_TMP;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The two-finger lift with `device = {...}` added to the index finger.
scripting::Scenario lift_with_index_device(const std::string& device) {
  std::string source = read_text(kLift);
  const std::string index = "{ name = \"index\", stiffness = 400, damping = 4, max_force = 10, trajectory = path(1) }";
  const auto at = source.find(index);
  REQUIRE(at != std::string::npos);
  source.replace(at, index.size(),
                 "{ name = \"index\", stiffness = 400, damping = 4, max_force = 10, trajectory = path(1), device = " +
                     device + " }");
  return scripting::Scenario::load_source(source, kLift);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const app::DeviceError& e) {
    return e.what();
  }
  return "";
}

// A registry with a test kind "fake": a mapped device held by the finger's script, given in the
// device frame (as a simulated Phantom's hand is), so the mapped device follows the script.
app::DeviceRegistry registry_with_fake() {
  app::DeviceRegistry r = app::default_registry();
  r.add({"fake", "fake", false, true, [](const app::DeviceContext& c) -> std::unique_ptr<hw::Device> {
           return std::make_unique<hw::ScriptedFinger>(c.hand_in_device_frame(), c.scenario.fingers()[c.finger].limits);
         }});
  return r;
}

app::RunOptions options_for(const app::DevicePlan& plan, const app::DeviceRegistry& registry,
                            const scripting::Scenario& scenario, const std::string& out) {
  app::RunOptions o;
  o.out = kTmp + "/" + out + ".h5";
  o.devices.record = plan.recorded();
  o.devices.script_alongside = plan.script_alongside;
  o.devices.make = [&plan, &registry, &scenario](std::size_t f) { return app::make_device(plan, registry, scenario, f); };
  return o;
}

std::vector<double> column(const std::string& trace, const std::string& path) {
  return recordings::read_dataset(trace, path).values;
}

}  // namespace

TEST_CASE("Device specs: defaults, overrides and errors that name the finger, the kinds or the field",
          "[e2e][devices]") {
  const auto scenario = scripting::Scenario::load(kLift);
  const app::DeviceRegistry registry = app::default_registry();

  const app::DevicePlan plain = app::plan_devices(scenario, {}, registry);
  REQUIRE(plain.specs.size() == 2);
  CHECK(plain.specs[0].kind == "scripted");
  CHECK(plain.specs[1].kind == "scripted");
  CHECK_FALSE(plain.any_real());
  CHECK(plain.recorded() == std::vector<bool>{false, false});

  const app::DevicePlan replayed = app::plan_devices(scenario, {"index=replay:x.h5"}, registry);
  CHECK(replayed.specs[0].kind == "scripted");
  CHECK(replayed.specs[1].kind == "replay");
  CHECK(replayed.specs[1].arg == "x.h5");
  CHECK(replayed.recorded() == std::vector<bool>{false, true});

  const auto plan = [&](std::vector<std::string> options) {
    return error_of([&] { app::plan_devices(scenario, options, registry); });
  };
  // An unknown finger lists the scenario's fingers.
  CHECK_THAT(plan({"pinky=scripted"}), Catch::Contains("no finger 'pinky'") && Catch::Contains("fingers: thumb, index"));
  // An unknown kind lists the kinds.
  CHECK_THAT(plan({"thumb=haptx"}), Catch::Contains("unknown device kind 'haptx'") &&
                                        Catch::Contains("scripted, replay:TRACE.h5, sim-phantom[:MODEL], udp:HOST:PORT, phantom:NAME"));
  CHECK_THAT(plan({"thumb"}), Catch::Contains("--device 'thumb': expected FINGER=SPEC"));
  CHECK_THAT(plan({"=scripted"}), Catch::Contains("expected FINGER=SPEC"));
  CHECK_THAT(plan({"thumb="}), Catch::Contains("empty device spec"));
  CHECK_THAT(plan({"thumb=replay"}), Catch::Contains("device 'replay' needs an argument: replay:TRACE.h5"));
  CHECK_THAT(plan({"thumb=scripted:x"}), Catch::Contains("takes no argument"));
  CHECK_THAT(plan({"thumb=scripted", "thumb=replay:a.h5"}), Catch::Contains("'thumb' already has a --device"));
  // Every kind is built into this binary (phantom: a clear error at open without the SDK); a
  // kind registered without a factory gives a clear error before anything opens.
  app::DeviceRegistry partial = registry;
  partial.add({"udp", "udp:HOST:PORT", true, true, nullptr});
  CHECK_THAT(error_of([&] { app::plan_devices(scenario, {"index=udp:127.0.0.1:7001"}, partial); }),
             Catch::Contains("not built into this binary") &&
                 Catch::Contains("built: scripted, replay:TRACE.h5, sim-phantom[:MODEL], phantom:NAME"));
  // The scenario's own default is checked the same way, named by its field.
  const auto bad_default = lift_with_index_device("{ default = \"nope\" }");
  CHECK_THAT(error_of([&] { app::plan_devices(bad_default, {}, registry); }),
             Catch::Contains("fingers[2] 'index': device.default: unknown device kind 'nope'"));
  // ... and --device overrides it.
  CHECK(app::plan_devices(bad_default, {"index=scripted"}, registry).specs[1].kind == "scripted");
}

TEST_CASE("Scenario device fields: errors name the field", "[e2e][devices]") {
  const auto error = [](const std::string& device) {
    try {
      lift_with_index_device(device);
    } catch (const scripting::ScenarioError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK_THAT(error("{ scale = 0 }"), Catch::Contains("fingers[2] 'index': device.scale: must be > 0"));
  CHECK_THAT(error("{ scale = -1 }"), Catch::Contains("device.scale: must be > 0"));
  CHECK_THAT(error("{ offset = { 1, 2 } }"), Catch::Contains("device.offset"));
  CHECK_THAT(error("{ rotation = 'x' }"), Catch::Contains("device.rotation"));
  CHECK_THAT(error("{ scael = 2 }"), Catch::Contains("unknown field 'scael'"));
  CHECK_THAT(error("{ default = 3 }"), Catch::Contains("device.default: expected a string"));
  const auto ok = lift_with_index_device("{ scale = 2, offset = { 0.1, 0, 0 }, rotation = { 0, 0, 0.5 } }");
  CHECK(ok.fingers()[1].mapping.scale == 2.0);
  CHECK(ok.fingers()[1].mapping.offset == hw::Vec3(0.1, 0, 0));
  CHECK(ok.fingers()[1].mapping.rotation == hw::Vec3(0, 0, 0.5));
  CHECK(ok.fingers()[0].mapping.is_identity());
}

TEST_CASE("A finger run with --device index=replay:TRACE reproduces the recording of that finger's run, bit for bit",
          "[e2e][devices][replay]") {
  // Law: the engine is a deterministic function of its inputs. The index finger fed from its
  // recorded hip and gimbal (and the thumb scripted as in the recording) gives the same inputs, hence the
  // same state hash at every physics tick and the same /servo rows, bit for bit (no tolerance).
  const auto scenario = scripting::Scenario::load(kLift);
  app::RunOptions rec;
  rec.out = kTmp + "/devices_recording.h5";
  REQUIRE(app::run_scenario(scenario, rec).error.empty());

  const app::DeviceRegistry registry = app::default_registry();
  const app::DevicePlan plan = app::plan_devices(scenario, {"index=replay:" + rec.out}, registry);
  const app::RunOptions options = options_for(plan, registry, scenario, "devices_index_replayed");
  const app::RunResult result = app::run_scenario(scenario, options);
  INFO(result.error);
  REQUIRE(result.error.empty());
  CHECK(result.passed());
  for (const char* path : {"/physics/state_hash", "/servo/fingers/index/hip", "/servo/fingers/index/force",
                           "/servo/fingers/thumb/hip", "/physics/objects/box/position"}) {
    INFO(path);
    const auto a = recordings::read_dataset(rec.out, path), b = recordings::read_dataset(options.out, path);
    CHECK(a.bits == b.bits);
    REQUIRE(a.values.size() == b.values.size());
    CHECK(std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(double)) == 0);
  }
  // The replayed finger's samples are recorded: device frame = world for a replay.
  CHECK(column(options.out, "/devices/index/position") == column(rec.out, "/servo/fingers/index/hip"));
  CHECK(column(options.out, "/devices/index/force") == column(options.out, "/servo/fingers/index/force"));
  CHECK_FALSE(recordings::has_object(options.out, "/devices/thumb"));

  // A trace too short for the run, or from another rate, is refused naming the file.
  const app::DevicePlan longer = app::plan_devices(scenario, {"index=replay:" + rec.out}, registry);
  scripting::LoadOptions load;
  load.sets = {"duration=5"};
  const auto five = scripting::Scenario::load(kLift, load);
  CHECK_THAT(error_of([&] { app::make_device(longer, registry, five, 1); }),
             Catch::Contains("holds 12000 servo ticks of finger 'index', but the run needs 15000"));
  load.sets = {"rates.servo=1500", "rates.haptic=500"};
  const auto slow = scripting::Scenario::load(kLift, load);
  CHECK_THAT(error_of([&] { app::make_device(longer, registry, slow, 1); }),
             Catch::Contains(rec.out) && Catch::Contains("rate_servo = 3000 Hz"));
  CHECK_THAT(error_of([&] { app::make_device(longer, registry, scenario, 1); }), Catch::Equals(""));
  const app::DevicePlan missing = app::plan_devices(scenario, {"index=replay:" + kTmp + "/no_such.h5"}, registry);
  CHECK_THAT(error_of([&] { app::make_device(missing, registry, scenario, 1); }), Catch::Contains("no_such.h5: no such file"));
}

TEST_CASE("A mapped device session: /devices holds device-frame samples and forces, and replays bit for bit",
          "[e2e][devices][mapping][replay]") {
  // The index finger's device has a workspace (scale 2, an offset, a rotation). Laws checked on
  // every servo row: world hip = offset + s R p_device, and force_device = R^T force_world
  // (no scale), within 1e-15 m and 1e-14 N (the same double operations MappedDevice does, so in
  // practice exact; a tolerance of a few ulp of 0.1 m and 10 N in case the compiler orders them
  // differently). Then `graspsim replay` of the session reproduces every dataset bit for bit,
  // /devices included (fed from the device samples through the recorded mapping).
  const auto scenario = lift_with_index_device(
      "{ default = \"fake\", scale = 2, offset = { 0.01, -0.02, 0.03 }, rotation = { 0.1, -0.2, 0.3 } }");
  const app::DeviceRegistry registry = registry_with_fake();
  const app::DevicePlan plan = app::plan_devices(scenario, {}, registry);
  CHECK(plan.recorded() == std::vector<bool>{false, true});
  const app::RunOptions options = options_for(plan, registry, scenario, "devices_mapped");
  const app::RunResult result = app::run_scenario(scenario, options);
  INFO(result.error);
  REQUIRE(result.error.empty());
  CHECK(result.passed());   // the mapped device follows the script: the lift still works

  const hw::WorkspaceMapping& m = scenario.fingers()[1].mapping;
  const Eigen::Matrix3d r = m.rotation_matrix();
  const auto p = column(options.out, "/devices/index/position");
  const auto hip = column(options.out, "/servo/fingers/index/hip");
  const auto fd = column(options.out, "/devices/index/force");
  const auto fw = column(options.out, "/servo/fingers/index/force");
  REQUIRE(p.size() == hip.size());
  double worst_p = 0.0, worst_f = 0.0, largest_force = 0.0;
  for (std::size_t i = 0; i + 2 < p.size(); i += 3) {
    const hw::Vec3 world = m.offset + m.scale * (r * hw::Vec3(p[i], p[i + 1], p[i + 2]));
    worst_p = std::max(worst_p, (world - hw::Vec3(hip[i], hip[i + 1], hip[i + 2])).norm());
    const hw::Vec3 f(fw[i], fw[i + 1], fw[i + 2]);
    worst_f = std::max(worst_f, (r.transpose() * f - hw::Vec3(fd[i], fd[i + 1], fd[i + 2])).norm());
    largest_force = std::max(largest_force, f.norm());
  }
  CHECK(worst_p <= 1e-15);
  CHECK(worst_f <= 1e-14);
  CHECK(largest_force > 1.0);   // the finger did push: the force law was exercised
  CHECK(recordings::read_string_attribute(options.out, "/devices/index", "mapping").rfind("scale 2;", 0) == 0);

  const app::ReplayPlan replay = app::load_replay(options.out);
  const app::RunResult again = app::run_scenario(*replay.scenario, replay.run_options(kTmp + "/devices_mapped.replay.h5"));
  INFO(again.error);
  REQUIRE(again.error.empty());
  recordings::CompareOptions bitwise;
  bitwise.bitwise = true;
  const auto diff = recordings::compare_traces(options.out, kTmp + "/devices_mapped.replay.h5", bitwise);
  CHECK(diff.same());
  bool devices_compared = false;
  for (const auto& l : diff.loops) UNSCOPED_INFO("compared " << l.loop << ": " << l.matched << " ticks");
  for (const std::string& note : diff.notes) UNSCOPED_INFO("note: " << note);
  for (const auto& l : diff.loops) devices_compared |= l.loop.find("devices") != std::string::npos && l.matched == 12000;
  CHECK(devices_compared);
}

namespace {

// A device that follows the finger's script, remembers every force it was sent, and can throw or
// raise the interrupt at a chosen tick.
struct Watch {
  hw::Vec3 last{1.0, 1.0, 1.0};   // N: the last force output (starts non-zero)
  double largest = 0.0;           // N: the largest force output
  int outputs = 0;
};
class WatchedFinger final : public hw::Device {
 public:
  WatchedFinger(std::unique_ptr<hw::Trajectory> t, Watch& w, std::int64_t fail_at, std::atomic<bool>* raise_at_fail)
      : t_(std::move(t)), w_(w), fail_at_(fail_at), raise_(raise_at_fail) {}
  hw::DeviceSample read(std::int64_t tick, double time) override {
    if (tick == fail_at_) {
      if (raise_) raise_->store(true);
      else throw std::runtime_error("device lost at tick " + std::to_string(tick));
    }
    hw::DeviceSample s;
    s.position = t_->sample(time).position;
    return s;
  }
  hw::DeviceLimits limits() const override { return {10.0}; }
  std::string describe() const override { return "watched"; }

 protected:
  void output(const hw::Vec3& f) override {
    w_.last = f;
    w_.largest = std::max(w_.largest, f.norm());
    ++w_.outputs;
  }

 private:
  std::unique_ptr<hw::Trajectory> t_;
  Watch& w_;
  std::int64_t fail_at_;
  std::atomic<bool>* raise_;
};

}  // namespace

TEST_CASE("Every device is released (zero force) at the end, on a device error and on Ctrl-C",
          "[e2e][devices][safety]") {
  // The safety rule: whatever ends the run, the last force each device is sent is exactly zero,
  // and it was pushing before (largest > 1 N: the grip is 4 N), so the test can fail.
  const auto scenario = scripting::Scenario::load(kLift);
  for (const std::string how : {"end", "error", "interrupt"}) {
    DYNAMIC_SECTION(how) {
      std::vector<Watch> watch(2);
      std::atomic<bool> interrupt{false};
      // Tick 7000 (2.33 s): both fingers grip the box and lift it.
      const std::int64_t at = how == "end" ? -1 : 7000;
      app::RunOptions o;
      o.out = kTmp + "/devices_release_" + how + ".h5";
      o.stop.interrupt = &interrupt;
      o.devices.make = [&](std::size_t f) -> std::unique_ptr<hw::Device> {
        return std::make_unique<WatchedFinger>(scenario.make_trajectory(f), watch[f], f == 1 ? at : -1,
                                               how == "interrupt" ? &interrupt : nullptr);
      };
      const app::RunResult r = app::run_scenario(scenario, o);
      if (how == "end") CHECK(r.error.empty());
      if (how == "error") CHECK_THAT(r.error, Catch::Contains("device lost at tick 7000"));
      if (how == "interrupt") CHECK(r.interrupted);
      for (const Watch& w : watch) {
        CHECK(w.largest > 1.0);
        CHECK(w.last == hw::Vec3::Zero());
        CHECK(std::signbit(w.last.x()) == false);
      }
    }
  }
}

TEST_CASE("graspsim run --device: bad specs exit 2 before writing, a replayed finger runs", "[e2e][devices][cli]") {
  const std::string cli = GRASPSIM_CLI;
  const std::string out = kTmp + "/devices_cli.h5";
  std::remove(out.c_str());
  auto r = graspsim::test::shell(cli + " run " + kLift + " --out " + out + " --device pinky=scripted");
  CHECK(r.status == 2);
  CHECK_THAT(r.output, Catch::Contains("no finger 'pinky'") && Catch::Contains("fingers: thumb, index"));
  r = graspsim::test::shell(cli + " run " + kLift + " --out " + out + " --device thumb=haptx");
  CHECK(r.status == 2);
  CHECK_THAT(r.output, Catch::Contains("unknown device kind 'haptx'"));
  r = graspsim::test::shell(cli + " run " + kLift + " --out " + out + " --device");
  CHECK(r.status == 2);
  CHECK_THAT(r.output, Catch::Contains("--device needs FINGER=SPEC"));
  std::ifstream none(out);
  CHECK_FALSE(none.good());   // nothing written
  // A device that cannot open (here: no OpenHaptics in this build) is not a bad spec: exit 2
  // with the reason, and the trace says the run stopped before its first tick.
  const std::string unopened = kTmp + "/devices_cli_phantom.h5";
  r = graspsim::test::shell(cli + " run " + kLift + " --out " + unopened + " --device 'index=phantom:Default PHANToM'");
  CHECK(r.status == 2);
  CHECK_THAT(r.output, Catch::Contains("OpenHaptics") && Catch::Contains("Default PHANToM"));

  const std::string first = kTmp + "/devices_cli_first.h5";
  REQUIRE(graspsim::test::shell(cli + " run " + kLift + " --quiet --out " + first).status == 0);
  r = graspsim::test::shell(cli + " run " + kLift + " --out " + out + " --device index=replay:" + first);
  INFO(r.output);
  CHECK(r.status == 0);
  CHECK(recordings::read_dataset(out, "/physics/state_hash").bits ==
        recordings::read_dataset(first, "/physics/state_hash").bits);
  CHECK_THAT(recordings::read_string_attribute(out, "/", "devices"), Catch::Contains("index: replay of " + first));
}

TEST_CASE("Every library scenario with its first finger on replay: reproduces its run bit for bit",
          "[e2e][devices][replay][scenarios]") {
  // Replay of a device session, library-wide: for each scenario in scenarios/, a scripted run, then
  // the same scenario with its first finger switched to replay:<that run> (the other fingers still
  // scripted, Lua feedback controllers included) gives the same state hash at every physics tick
  // and the same expectation results (law: determinism in the inputs; no tolerance).
  const std::vector<std::string> files = graspsim::test::library_scenarios();
  REQUIRE(files.size() >= 20);
  const app::DeviceRegistry registry = app::default_registry();
  for (const std::string& file : files) {
    INFO(file);
    const auto scenario = scripting::Scenario::load(file);
    if (scenario.model().fingers.empty()) continue;   // a free body or a drop: nothing to drive
    app::RunOptions rec;
    rec.out = kTmp + "/devices_lib_rec.h5";
    const app::RunResult first = app::run_scenario(scenario, rec);
    REQUIRE(first.error.empty());
    const std::string finger = scenario.model().fingers.front().name;
    const app::DevicePlan plan = app::plan_devices(scenario, {finger + "=replay:" + rec.out}, registry);
    const app::RunOptions options = options_for(plan, registry, scenario, "devices_lib_replayed");
    const app::RunResult again = app::run_scenario(scenario, options);
    INFO(again.error);
    REQUIRE(again.error.empty());
    CHECK(recordings::read_dataset(rec.out, "/physics/state_hash").bits ==
          recordings::read_dataset(options.out, "/physics/state_hash").bits);
    REQUIRE(first.expectations.size() == again.expectations.size());
    for (std::size_t i = 0; i < first.expectations.size(); ++i) CHECK(first.expectations[i].passed == again.expectations[i].passed);
  }
}

TEST_CASE("The run loop sends each device the demand itself: the one force ramp is the device's force safety", "[e2e][devices][safety]") {
  // Law: rendered(t) = clamp(demand) from t = 0, with the 10 N clamp of a scripted finger; below
  // it that is the demand itself, compared bitwise (clamp_force returns it untouched). The lift
  // grips from 1 s, so loaded ticks inside the first seconds are seen: a run ramp scaling by
  // t / T_r there (T_r of 0.5 s or 2 s, say) would differ on every one of them. The ramp
  // lives in each device's ForceSafety (tests/hw/test_force_safety.cpp), after this point; the
  // trace says nothing of a run ramp.
  const auto scenario = scripting::Scenario::load(kLift);
  app::RunOptions plain;
  plain.out = kTmp + "/ramp_none.h5";
  REQUIRE(app::run_scenario(scenario, plain).error.empty());
  const auto f = column(plain.out, "/servo/fingers/index/force");
  const auto d = column(plain.out, "/servo/fingers/index/force_demand");
  const auto t = column(plain.out, "/servo/time");
  std::size_t loaded = 0, mismatches = 0;
  for (std::size_t n = 0; n < t.size(); ++n) {
    const hw::Vec3 demand(d[3 * n], d[3 * n + 1], d[3 * n + 2]);
    const hw::Vec3 got(f[3 * n], f[3 * n + 1], f[3 * n + 2]);
    if (demand.norm() > 1.0 && t[n] < 2.0) ++loaded;
    if (demand.norm() < 10.0 && got != demand) ++mismatches;
  }
  CHECK(loaded > 1000);   // contact forces inside the first 2 s, where a run ramp would act
  CHECK(mismatches == 0);
  CHECK_FALSE(recordings::has_attribute(plain.out, "/", "force_ramp"));
}

// Every finger on the simulated Phantom: the run is recorded with /devices/<finger>
// (the device's own samples) and replays bit for bit. The stylus is held by a 300 N/m hand and
// the Premium 1.5's force is derated to its continuous 1.4 N: the lift's expectations are the
// scenario's business (here they fail: too weak a grip for a 0.2 kg box), the replay is ours.
TEST_CASE("A run with every finger on sim-phantom records its samples and replays bit for bit", "[e2e][devices]") {
  const std::string cli = GRASPSIM_CLI;
  const std::string out = kTmp + "/devices_sim_phantom.h5";
  const auto run = graspsim::test::shell(cli + " run " + kLift + " --quiet --duration 2 --out " + out +
                                         " --device thumb=sim-phantom --device index=sim-phantom:omni");
  INFO(run.output);
  CHECK(run.status != 2);
  CHECK_THAT(graspsim::recordings::read_string_attribute(out, "/devices/index", "device"), Catch::Contains("Omni"));
  CHECK(graspsim::recordings::read_dataset(out, "/devices/thumb/position").shape.at(0) == 6000);
  const auto replay = graspsim::test::shell(cli + " replay " + out + " --out " + kTmp + "/devices_sim_phantom_replay.h5");
  INFO(replay.output);
  CHECK_THAT(replay.output, Catch::Contains("reproduced  bit for bit"));
}

TEST_CASE("A device trace written before the sample counter columns still replays bit for bit", "[e2e][devices][replay]") {
  // A device table without /devices/<finger>/sequence and new_samples, as a trace from a build
  // without the sample counter has it (here: the same run with RunOptions::Devices::counters off,
  // which writes exactly that table); its replay must write neither column, or compare refuses
  // the tables' different columns and the replay reports 'differs'.
  const auto scenario = scripting::Scenario::load(kLift);
  const app::DeviceRegistry registry = app::default_registry();
  const app::DevicePlan plan = app::plan_devices(scenario, {"thumb=sim-phantom"}, registry);
  app::RunOptions options = options_for(plan, registry, scenario, "devices_old_schema");
  options.devices.counters = false;
  const app::RunResult run = app::run_scenario(scenario, options);
  REQUIRE(run.error.empty());
  CHECK_THROWS(recordings::read_dataset(options.out, "/devices/thumb/sequence"));
  const auto replay = graspsim::test::shell(std::string(GRASPSIM_CLI) + " replay " + options.out + " --out " + kTmp +
                                            "/devices_old_schema_replay.h5");
  INFO(replay.output);
  CHECK_THAT(replay.output, Catch::Contains("reproduced  bit for bit"));
  CHECK_THROWS(recordings::read_dataset(kTmp + "/devices_old_schema_replay.h5", "/devices/thumb/sequence"));
}
