// The two-finger lift end to end: Lua scenario -> scripted devices -> engine -> HDF5 trace.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <string>

#include "app/run.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/scripting/scenario.hpp"

using namespace graspsim;

namespace {
const std::string kScenario = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/two_finger_lift.lua";
const std::string kTmp = GRASPSIM_TEST_TMP;
}  // namespace

// The paper's two-point grasp: the scenario's own expectations (grip before the lift, a rise of
// at least 5 cm, the box still at the end, under 2 mm of slip per finger) hold at the paper's
// rates, and at 500 Hz physics, where the same hand motion must lift the box just as well.
TEST_CASE("the two-finger lift lifts the box and meets its expectations", "[e2e][scenario]") {
  for (const char* physics : {"50", "500"}) {
    scripting::LoadOptions load;
    load.sets.push_back(std::string("rates.physics=") + physics);
    const auto scenario = scripting::Scenario::load(kScenario, load);
    app::RunOptions options;
    options.out = kTmp + "/e2e_lift_" + physics + ".h5";
    const app::RunResult result = app::run_scenario(scenario, options);
    INFO("physics " << physics << " Hz: " << result.error);
    REQUIRE(result.error.empty());
    REQUIRE(result.expectations.size() == 5);
    for (const auto& e : result.expectations) {
      INFO(e.what << ": " << e.detail);
      CHECK(e.passed);
    }
  }
}

// The trace holds every tick of every loop: 4 s at 3000/500/50 Hz is 12000 servo, 2000 haptic
// and 200 physics rows; every dataset the schema names is there with its width and units, and
// the root says the run completed and carries the scenario's text.
TEST_CASE("the two-finger lift's trace has every dataset with the right lengths", "[e2e][trace]") {
  const auto scenario = scripting::Scenario::load(kScenario);
  app::RunOptions options;
  options.out = kTmp + "/e2e_lift_trace.h5";
  const app::RunResult result = app::run_scenario(scenario, options);
  REQUIRE(result.passed());
  const std::string& f = options.out;
  struct Expect { std::string path; std::size_t rows, width; std::string units; };
  std::vector<Expect> expected = {
      {"/servo/tick", 12000, 1, "tick"}, {"/servo/time", 12000, 1, "s"},
      {"/haptic/tick", 2000, 1, "tick"}, {"/haptic/time", 2000, 1, "s"},
      {"/physics/tick", 200, 1, "tick"}, {"/physics/time", 200, 1, "s"}};
  for (const char* finger : {"thumb", "index"}) {
    const std::string s = std::string("/servo/fingers/") + finger + "/";
    const std::string h = std::string("/haptic/fingers/") + finger + "/";
    expected.push_back({s + "hip", 12000, 3, "m"});
    expected.push_back({s + "force", 12000, 3, "N"});
    expected.push_back({h + "god_object", 2000, 3, "m"});
    expected.push_back({h + "surface_point", 2000, 3, "m"});
    expected.push_back({h + "depth", 2000, 1, "m"});
    expected.push_back({h + "friction_radius", 2000, 1, "m"});
    expected.push_back({h + "force", 2000, 3, "N"});
    expected.push_back({h + "state", 2000, 1, "1"});
  }
  for (const char* q : {"position", "velocity", "angular_velocity", "force", "torque"}) {
    const std::string units = std::string(q) == "position" ? "m" : std::string(q) == "velocity" ? "m/s"
                            : std::string(q) == "angular_velocity" ? "rad/s" : std::string(q) == "force" ? "N" : "N m";
    expected.push_back({std::string("/physics/objects/box/") + q, 200, 3, units});
  }
  expected.push_back({"/physics/objects/box/quaternion", 200, 4, "1"});
  for (const Expect& e : expected) {
    INFO(e.path);
    const recordings::Dataset d = recordings::read_dataset(f, e.path);
    REQUIRE(d.shape.at(0) == e.rows);
    REQUIRE((e.width == 1 ? d.shape.size() == 1 : d.shape.at(1) == e.width));
    REQUIRE(d.units == e.units);
  }
  // Time is tick / servo rate, exactly.
  const auto ticks = recordings::read_dataset(f, "/physics/tick").values;
  const auto times = recordings::read_dataset(f, "/physics/time").values;
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    REQUIRE(ticks[i] == 60.0 * static_cast<double>(i));
    REQUIRE(times[i] == ticks[i] / 3000.0);
  }
  CHECK(recordings::read_string_attribute(f, "/", "status") == "complete");
  CHECK(recordings::read_string_attribute(f, "/", "scenario_source") == scenario.source());
  CHECK(recordings::read_int_attribute(f, "/", "rate_physics") == 50);
  // The trace shows the lift: the box's last recorded height is over 5 cm above its first.
  const auto pos = recordings::read_dataset(f, "/physics/objects/box/position").values;
  CHECK(pos[pos.size() - 1] - pos[2] > 0.05);
}

// Determinism: the same scenario and seed give the same trace, bit for bit. Two runs in one
// process must agree on every value of every loop (tolerance zero). Across processes and
// builds: tests/golden/test_golden.cpp.
TEST_CASE("the same scenario run twice gives a bit-identical trace", "[e2e][determinism]") {
  const auto scenario = scripting::Scenario::load(kScenario);
  std::vector<std::string> files;
  for (int i = 0; i < 2; ++i) {
    app::RunOptions options;
    options.out = kTmp + "/e2e_determinism_" + std::to_string(i) + ".h5";
    REQUIRE(app::run_scenario(scenario, options).passed());
    files.push_back(options.out);
  }
  const std::vector<std::string> datasets = {
      "/servo/fingers/thumb/force", "/servo/fingers/index/hip", "/haptic/fingers/thumb/god_object",
      "/haptic/fingers/index/force", "/physics/objects/box/position",
      "/physics/objects/box/quaternion", "/physics/objects/box/angular_velocity"};
  for (const std::string& d : datasets) {
    INFO(d);
    const auto a = recordings::read_dataset(files[0], d).values;
    const auto b = recordings::read_dataset(files[1], d).values;
    REQUIRE(a.size() == b.size());
    REQUIRE(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
  }
}
