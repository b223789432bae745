// Replay (README.md, "Replaying a trace"): a trace's scenario rerun with every finger fed from its
// recorded device samples reproduces the trace bit for bit (the state hash of every physics tick
// and every dataset, compared with the same code as `graspsim compare --bitwise`); a what-if replay
// with another mu keeps the hand motion and parts where friction first matters; bad input exits 2
// with a message naming the file and what is wrong, writing nothing.
#include <catch2/catch.hpp>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>
#include <vector>

#include "app/replay.hpp"
#include "app/run.hpp"
#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_compare.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "tests/support/shell.hpp"

using namespace graspsim;

namespace {

const std::string kCli = GRASPSIM_CLI;
const std::string kSource = GRASPSIM_SOURCE_DIR;
const std::string kScenarios = kSource + "/scenarios/";
const std::string kTmp = GRASPSIM_TEST_TMP;

using graspsim::test::Outcome;

Outcome cli(const std::string& args) { return graspsim::test::shell(kCli + " " + args); }

// Runs a scenario file (scripted fingers) into kTmp/<out>.h5, as `graspsim run` does.
std::string record(const std::string& scenario_path, const std::vector<std::string>& sets, const std::string& out) {
  scripting::LoadOptions load;
  load.sets = sets;
  const auto scenario = scripting::Scenario::load(scenario_path, load);
  app::RunOptions options;
  options.out = kTmp + "/" + out + ".h5";
  options.overrides = sets;
  const app::RunResult result = app::run_scenario(scenario, options);
  INFO(result.error);
  REQUIRE(result.error.empty());
  return options.out;
}

// Replays `trace` into kTmp/<out>.h5.
app::RunResult replay(const std::string& trace, const std::vector<std::string>& sets, const std::string& out) {
  app::ReplayOptions options;
  options.sets = sets;
  const app::ReplayPlan plan = app::load_replay(trace, options);
  return app::run_scenario(*plan.scenario, plan.run_options(kTmp + "/" + out + ".h5"));
}

std::vector<std::uint64_t> hashes(const std::string& trace) {
  return recordings::read_dataset(trace, "/physics/state_hash").bits;
}

recordings::CompareResult bitwise(const std::string& a, const std::string& b) {
  recordings::CompareOptions options;
  options.bitwise = true;
  return recordings::compare_traces(a, b, options);
}

// The replay of `scenario` is the recording, bit for bit.
void check_reproduced(const std::string& scenario, const std::string& name) {
  const std::string original = record(kScenarios + scenario, {}, "replay_" + name);
  const app::RunResult r = replay(original, {}, "replay_" + name + "_again");
  INFO(r.error);
  REQUIRE(r.error.empty());
  for (const auto& e : r.expectations) {   // the scenario's own checks still run, and hold
    INFO(e.what << ": " << e.detail);
    CHECK(e.passed);
  }
  // The state after every physics tick: one hash per tick, all equal.
  const std::vector<std::uint64_t> a = hashes(original), b = hashes(r.trace_path);
  REQUIRE(a.size() == static_cast<std::size_t>(r.physics_ticks));
  REQUIRE(a.size() > 10);
  CHECK(a == b);
  // Every dataset of every loop, as `graspsim compare --bitwise` sees it.
  const recordings::CompareResult c = bitwise(original, r.trace_path);
  for (const auto& d : c.datasets) {
    INFO(d.path);
    CHECK_FALSE(d.differs());
  }
  CHECK(c.same());
  CHECK(c.unmatched_ticks() == 0);
  // It says what it is: a replay of that file, whose devices were the recorded samples.
  CHECK(recordings::read_string_attribute(r.trace_path, "/", "replay_of") ==
        original + "\n" + recordings::read_string_attribute(original, "/", "scenario_source_hash"));
  CHECK_THAT(recordings::read_string_attribute(r.trace_path, "/", "devices"), Catch::Contains("replay of " + original));
}

// Copies a trace and sets one int64 root attribute in the copy.
std::string with_int_attribute(const std::string& trace, const std::string& out, const char* name, std::int64_t value) {
  std::filesystem::copy_file(trace, out, std::filesystem::copy_options::overwrite_existing);
  using recordings::inspect::File;
  File f = File::open(out, File::Mode::kReadWrite);
  REQUIRE(f.has_attribute("/", name));   // written in place, its stored type kept
  f.write_int_attribute("/", name, value);
  return out;
}

}  // namespace

TEST_CASE("replay of two_finger_lift is the recording bit for bit", "[e2e][replay]") {
  check_reproduced("two_finger_lift.lua", "lift");
}

// The pole's finger is a Lua feedback controller reading the simulation view: replayed, no Lua
// trajectory runs at all, and the recorded HIP alone reproduces every tick.
TEST_CASE("replay of pole_balance (a Lua feedback trajectory) is the recording bit for bit", "[e2e][replay]") {
  check_reproduced("pole_balance.lua", "pole");
}

// The thumb's scripted gimbal pitch turns the box: the recorded gimbal column is an input too.
TEST_CASE("replay of gimbal_twist (scripted gimbal pitch) is the recording bit for bit", "[e2e][replay]") {
  check_reproduced("gimbal_twist.lua", "gimbal");
}

// The thumb's script watches the rod through the simulation view and keeps the swing and the
// hand-to-centre band for the expectations: replayed, the scripts still run (their motion
// unused), so they see the same run and the expectations hold as they did.
TEST_CASE("replay of rod_swing (expectations fed by a watching script) is the recording bit for bit",
          "[e2e][replay]") {
  check_reproduced("rod_swing.lua", "rod");
}

// Relative mesh files resolve against the recorded scenario_path's directory.
TEST_CASE("replay of mesh_grasp reads its mesh from the recorded scenario's directory", "[e2e][replay]") {
  check_reproduced("mesh_grasp.lua", "mesh");
}

TEST_CASE("a what-if replay with another mu keeps the hand motion and parts where friction matters",
          "[e2e][replay]") {
  const std::string original = record(kScenarios + "two_finger_lift.lua", {}, "replay_whatif_src");
  const app::RunResult r = replay(original, {"mu=0.4"}, "replay_whatif");
  REQUIRE(r.error.empty());
  // The overrides of the new trace reload its own scenario: recorded ones, then the new one.
  CHECK(recordings::read_string_attribute(r.trace_path, "/", "overrides") == "mu=0.4\n");
  const recordings::CompareResult c = bitwise(original, r.trace_path);
  REQUIRE_FALSE(c.same());
  // Same hand: every finger's recorded HIP and gimbal are the replay's inputs, bit for bit.
  for (const auto& d : c.datasets) {
    if (d.quantity == "hip" || d.quantity == "gimbal") {
      INFO(d.path);
      CHECK_FALSE(d.differs());
    }
  }
  // The first physics tick whose state hash differs, found here from the two columns, is the
  // one compare names for physics/state_hash; nothing in /physics parts earlier.
  const std::vector<std::uint64_t> a = hashes(original), b = hashes(r.trace_path);
  REQUIRE(a.size() == b.size());
  std::size_t row = 0;
  while (row < a.size() && a[row] == b[row]) ++row;
  REQUIRE(row < a.size());
  const std::vector<double> ticks = recordings::read_dataset(original, "/physics/tick").values;
  const auto first_physics_tick = static_cast<std::int64_t>(ticks[row]);
  CHECK(first_physics_tick > 0);   // the fingers first had to reach the box
  bool found = false;
  for (const auto& d : c.datasets) {
    if (!d.differs()) continue;
    REQUIRE(d.first);
    if (d.loop == "physics") CHECK(d.first->tick >= first_physics_tick);
    if (d.path == "physics/state_hash") {
      found = true;
      CHECK(d.first->tick == first_physics_tick);
    }
  }
  CHECK(found);
  // The datasets are listed by first divergence: the first one parts no later than the hash.
  CHECK(c.datasets.front().first->tick <= first_physics_tick);
  // And the CLI says so, naming that tick, exit 1 from compare.
  const Outcome o = cli("compare " + original + " " + r.trace_path);
  INFO(o.output);
  CHECK(o.status == 1);
  CHECK_THAT(o.output, Catch::Contains("tick " + std::to_string(c.datasets.front().first->tick)));
}

TEST_CASE("graspsim replay: reproduces, says so, and a what-if names where it parts", "[e2e][replay][cli]") {
  const std::string original = kTmp + "/replay_cli_src.h5";
  REQUIRE(cli("run " + kScenarios + "two_finger_lift.lua --quiet --out " + original).status == 0);
  const std::string again = kTmp + "/replay_cli_again.h5";
  Outcome o = cli("replay " + original + " --out " + again);
  INFO(o.output);
  CHECK(o.status == 0);
  CHECK_THAT(o.output, Catch::Contains("reproduced  bit for bit"));
  CHECK_THAT(o.output, Catch::Contains("state_hash equal at all 200 physics ticks"));
  CHECK_THAT(o.output, Catch::Contains("PASS"));
  CHECK(cli("compare --bitwise " + original + " " + again).status == 0);

  const std::string whatif = kTmp + "/replay_cli_whatif.h5";
  o = cli("replay " + original + " --set mu=0.4 --out " + whatif);
  INFO(o.output);
  CHECK_THAT(o.output, Catch::Contains("what if     mu=0.4"));
  CHECK_THAT(o.output, Catch::Contains("parts       from the recording at"));
  CHECK(cli("compare " + original + " " + whatif).status == 1);
}

TEST_CASE("a trace stopped by an error replays up to its last recorded tick", "[e2e][replay]") {
  // The script fails at t = 0.5 s: the recording holds ticks 0 .. 1499 and says "error: ...".
  scripting::LoadOptions load;
  const auto scenario = scripting::Scenario::load(kSource + "/tests/e2e/data/error_midway.lua", load);
  app::RunOptions options;
  options.out = kTmp + "/replay_cut_src.h5";
  const app::RunResult original = app::run_scenario(scenario, options);
  REQUIRE_FALSE(original.error.empty());
  const app::ReplayPlan plan = app::load_replay(options.out);
  CHECK(plan.recorded_ticks == original.servo_ticks);
  REQUIRE(plan.notes.size() == 1);
  CHECK_THAT(plan.notes[0], Catch::Contains("replaying t = 0 to 0.5 s"));
  const app::RunResult r = app::run_scenario(*plan.scenario, plan.run_options(kTmp + "/replay_cut.h5"));
  INFO(r.error);
  CHECK(r.error.empty());
  CHECK(r.servo_ticks == original.servo_ticks);
  CHECK(hashes(options.out) == hashes(r.trace_path));
  CHECK(bitwise(options.out, r.trace_path).same());
}

TEST_CASE("graspsim replay refuses bad input with exit 2 and writes nothing", "[e2e][replay][cli]") {
  const std::string good = record(kScenarios + "two_finger_lift.lua", {}, "replay_bad_src");
  const std::string out = kTmp + "/replay_bad_out.h5";
  std::filesystem::remove(out);
  const auto refused = [&](const std::string& args, const std::string& message) {
    const Outcome o = cli("replay " + args + " --out " + out);
    INFO(args << "\n" << o.output);
    CHECK(o.status == 2);
    CHECK_THAT(o.output, Catch::Contains(message));
    CHECK_FALSE(std::filesystem::exists(out));
  };
  SECTION("a missing file") { refused(kTmp + "/no_such_trace.h5", "no_such_trace.h5: no such file"); }
  SECTION("not HDF5") { refused(kScenarios + "two_finger_lift.lua", "two_finger_lift.lua"); }
  SECTION("a schema 1 trace has no device inputs") {
    const std::string old = with_int_attribute(good, kTmp + "/replay_schema1.h5", "schema_version", 1);
    refused(old, "schema_version 1 records no device inputs");
  }
  SECTION("a finger of the scenario missing from the trace") {
    refused(good + " --set fingers.thumb.name=pinky",
            "the scenario's finger 'pinky' has no recorded inputs (/servo/fingers/pinky/hip and gimbal); "
            "fingers in the trace: thumb, index");
  }
  SECTION("rates changed by --set") {
    refused(good + " --set rates.physics=500",
            "the replay would run at rate_physics = 500 Hz, but the trace was recorded at 50 Hz");
  }
  SECTION("an unknown --set") { refused(good + " --set nu=0.4", "unknown field or param 'nu'"); }
  SECTION("--out is the trace itself") {
    const auto before = std::filesystem::last_write_time(good);
    const Outcome o = cli("replay " + good + " --out " + good);
    CHECK(o.status == 2);
    CHECK_THAT(o.output, Catch::Contains("would be written over"));
    CHECK(std::filesystem::last_write_time(good) == before);
  }
}

TEST_CASE("a relative mesh file missing at replay names where it was looked for", "[e2e][replay]") {
  // A copy of mesh_grasp in a directory without its meshes/.
  const std::string dir = kTmp + "/replay_moved";
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kScenarios + "mesh_grasp.lua", dir + "/mesh_grasp.lua",
                             std::filesystem::copy_options::overwrite_existing);
  std::filesystem::create_directories(dir + "/meshes");
  std::filesystem::copy_file(kScenarios + "meshes/wedge_mm.stl", dir + "/meshes/wedge_mm.stl",
                             std::filesystem::copy_options::overwrite_existing);
  const std::string trace = record(dir + "/mesh_grasp.lua", {}, "replay_moved");
  std::filesystem::remove_all(dir);
  const Outcome o = cli("replay " + trace + " --out " + kTmp + "/replay_moved_out.h5");
  INFO(o.output);
  CHECK(o.status == 2);
  CHECK_THAT(o.output, Catch::Contains("meshes/wedge_mm.stl"));
  CHECK_THAT(o.output, Catch::Contains("--scenario-dir DIR"));
  // Given the directory that holds meshes/, it replays, bit for bit.
  const Outcome again = cli("replay " + trace + " --scenario-dir " + kScenarios + " --out " + kTmp + "/replay_moved_out.h5");
  INFO(again.output);
  CHECK(again.status == 0);
  CHECK_THAT(again.output, Catch::Contains("reproduced  bit for bit"));
}
