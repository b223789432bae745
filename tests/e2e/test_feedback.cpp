// Feedback in scripted fingers: a trajectory function's second argument is a read-only view of
// the simulation as the last physics tick left it.
#include <catch2/catch.hpp>

#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "app/run.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/scripting/scenario.hpp"

using namespace graspsim;

namespace {
const std::string kData = std::string(GRASPSIM_SOURCE_DIR) + "/tests/e2e/data/";
const std::string kScenarios = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/";
const std::string kTmp = GRASPSIM_TEST_TMP;

int line_of(const std::string& path, const std::string& marker) {
  std::ifstream in(path);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.find(marker) != std::string::npos) return n;
  }
  FAIL("marker '" << marker << "' not in " << path);
  return 0;
}

app::RunResult run(const std::string& path, const std::vector<std::string>& sets, const std::string& out) {
  scripting::LoadOptions load;
  load.sets = sets;
  const auto scenario = scripting::Scenario::load(path, load);
  app::RunOptions options;
  options.out = kTmp + "/" + out + ".h5";
  return app::run_scenario(scenario, options);
}
}  // namespace

// The probe's trajectory remembers what it saw; its checks compare that, bit for bit, with what
// a check sees at the same tick, and with the time and count of the physics ticks (see the file).
TEST_CASE("a trajectory function sees the state of the last physics tick", "[e2e][feedback]") {
  const app::RunResult result = run(kData + "view_probe.lua", {}, "feedback_probe");
  REQUIRE(result.error.empty());
  REQUIRE(result.expectations.size() == 4);
  for (const auto& e : result.expectations) {
    INFO(e.what << ": " << e.detail);
    CHECK(e.passed);
  }
}

TEST_CASE("a trajectory function cannot write the view: the error names the file and line",
          "[e2e][feedback]") {
  const std::string path = kData + "view_write.lua";
  const app::RunResult result = run(path, {}, "feedback_write");
  const std::string where = path + ":" + std::to_string(line_of(path, "-- WRITE")) + ":";
  CHECK_THAT(result.error, Catch::StartsWith(where + " the simulation view is read-only"));
  CHECK_THAT(result.error, Catch::Contains("fingers[1] 'probe' trajectory at t = 0.05"));
  // The box itself was not moved: it fell freely, nowhere near z = 2.
}

// Other ways to write, each refused where it is written: rawset (the view is a userdata),
// setmetatable (its metatable is protected), and a nested table.
TEST_CASE("rawset, setmetatable and nested writes on the view are refused", "[e2e][feedback]") {
  const std::vector<std::pair<std::string, std::string>> attempts = {
      {"rawset(sim, 'time', 0)", "bad argument #1 to 'rawset' (table expected, got userdata)"},
      {"setmetatable(sim.objects, nil)", "bad argument #1 to 'setmetatable' (table expected, got userdata)"},
      {"sim.fingers.probe.hip = {0, 0, 0}", "the simulation view is read-only (cannot set field 'hip')"},
      {"sim.objects.box.rotation[1][2] = 1", "the simulation view is read-only (cannot set an element)"},
      {"getmetatable(sim).__index = {}", "attempt to index a string value"},
  };
  for (const auto& [code, message] : attempts) {
    const std::string path = kTmp + "/feedback_attempt.lua";
    {
      std::ofstream f(path);
      f << "return { duration = 0.02,\n"
           "  objects = { { name = 'box', size = {0.04, 0.04, 0.04}, mass = 0.1 } },\n"
           "  fingers = { { name = 'probe', trajectory = function(t, sim)\n"
           "    if t > 0 then " << code << " end\n"
           "    return 1, 0, 0 end } } }\n";
    }
    const app::RunResult result = run(path, {}, "feedback_attempt");
    INFO(code);
    CHECK_THAT(result.error, Catch::StartsWith(path + ":4: "));
    CHECK_THAT(result.error, Catch::Contains(message));
  }
}

// Deterministic: the view holds only simulation state, so a feedback controller's run is the
// same bit for bit. Loaded twice, so that no Lua state carries over between the runs.
TEST_CASE("a feedback scenario run twice gives a bit-identical trace", "[e2e][feedback][determinism]") {
  std::vector<std::string> files;
  for (int i = 0; i < 2; ++i) {
    const app::RunResult result = run(kScenarios + "pole_balance.lua", {"duration=1"}, "feedback_twice_" + std::to_string(i));
    REQUIRE(result.error.empty());
    files.push_back(kTmp + "/feedback_twice_" + std::to_string(i) + ".h5");
  }
  for (const std::string d : {"/servo/fingers/finger/hip", "/servo/fingers/finger/force",
                              "/physics/objects/pole/position", "/physics/objects/pole/quaternion"}) {
    INFO(d);
    const auto a = recordings::read_dataset(files[0], d).values;
    const auto b = recordings::read_dataset(files[1], d).values;
    REQUIRE(a.size() == b.size());
    REQUIRE(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
  }
}

// pole_balance's controller is what keeps the pole up: with its gain at zero the finger stays
// put and the pole falls, so the scenario's "within a few degrees of upright" fails.
TEST_CASE("without its controller the pole falls", "[e2e][feedback][scenario]") {
  const app::RunResult result = run(kScenarios + "pole_balance.lua", {"gain=0"}, "pole_no_gain");
  bool upright_failed = false;
  for (const auto& e : result.expectations) {
    if (e.what.find("upright") != std::string::npos) upright_failed = upright_failed || !e.passed;
  }
  INFO(result.error);
  CHECK(upright_failed);
}

// Scripted pitch reaches the engine's input: in gimbal_twist the thumb's waypoint pitch goes
// from 0 to the `pitch` parameter, and the engine turns the box by each physics step's pitch
// change (section 3.2, solution 1), which the trace records as `twist`. So the twists over the
// run sum to the whole pitch change, here -45 degrees (the sign too), up to the rounding of the
// ~150 steps' differences (1e-12 rad); and the scenario's own expectations hold.
TEST_CASE("a scripted gimbal pitch turns the box by the pitch change end to end", "[e2e][gimbal]") {
  const app::RunResult result = run(kScenarios + "gimbal_twist.lua", {"pitch=-45"}, "gimbal_pitch");
  REQUIRE(result.error.empty());
  for (const auto& e : result.expectations) {
    INFO(e.what << ": " << e.detail);
    CHECK(e.passed);
  }
  const auto twist = recordings::read_dataset(kTmp + "/gimbal_pitch.h5", "/physics/objects/box/twist").values;
  double sum = 0.0;
  for (double x : twist) sum += x;
  CHECK(sum == Approx(-M_PI / 4).margin(1e-12));
}
