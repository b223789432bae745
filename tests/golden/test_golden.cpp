// Golden regressions and determinism: every scenario reruns and matches its golden trace bit for
// bit; the same scenario gives the same trace in one process, in two processes and from a Debug and
// a Release build. README.md, "Golden traces" and "Determinism".
#include <catch2/catch.hpp>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "app/replay.hpp"
#include "app/golden.hpp"
#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "tests/support/shell.hpp"
#include "tests/support/library.hpp"
#include "tests/support/skip.hpp"
#include "tests/support/trace_edit.hpp"

namespace fs = std::filesystem;
using namespace graspsim;

namespace {

const std::string kSource = GRASPSIM_SOURCE_DIR;
const std::string kGoldenDir = kSource + "/tests/golden";
const std::string kTmp = GRASPSIM_TEST_TMP;

std::vector<std::string> scenario_files() { return graspsim::test::library_scenarios(); }

using graspsim::test::Outcome;
using graspsim::test::shell;

// Adds `delta` to element (row, component) of a float64 column, in place.
void perturb(const std::string& file, const std::string& path, std::uint64_t row, std::uint64_t component,
             double delta) {
  graspsim::test::add_to_element(file, path, row, component, delta);
}

// Replaces the root string attribute `name` (a golden "written elsewhere").
void set_root_string(const std::string& file, const std::string& name, const std::string& value) {
  using recordings::inspect::File;
  File::open(file, File::Mode::kReadWrite).write_string_attribute("/", name, value);
}

}  // namespace

// Goldens. Each scenario reruns in process at its own rates (as `tools/bless` ran it) and its
// full trace is compared bitwise with the golden through recordings::compare_traces: every
// golden row (all /physics rows with the state hash, /servo and /haptic at physics ticks) must
// find its tick and be bit-identical. A failure names the first diverging tick and quantity and
// the command that re-blesses; a scenario without a golden fails with that command.
TEST_CASE("every scenario in scenarios/ reruns bit-identical to its golden trace", "[golden]") {
  const auto files = scenario_files();
  REQUIRE(files.size() >= 13);
  for (const std::string& file : files) {
    const std::string golden = golden::golden_path(kGoldenDir, file);
    const std::string fresh = kTmp + "/golden_run_" + fs::path(file).stem().string() + ".h5";
    INFO(file);
    if (!fs::exists(golden)) {
      FAIL_CHECK("no golden trace " << golden << " for " << file << ": bless one with "
                                    << golden::bless_command(file) << " and commit it");
      continue;
    }
    const app::RunResult run = golden::run_for_golden(file, fresh);
    INFO("run error: " << run.error);
    CHECK(run.error.empty());
    // A golden is a passing run: the rerun meets every expectation, and so did the run the
    // golden holds (a bless with --allow-failing would otherwise pass here unseen).
    for (const auto& e : run.expectations) {
      INFO(e.what << ": " << e.detail);
      CHECK(e.passed);
    }
    CHECK(run.expectations.size() > 0);
    CHECK_THAT(recordings::read_string_attribute(golden, "/", "expectations"),
               !Catch::Contains("FAIL ") && Catch::StartsWith("PASS "));
    const golden::GoldenCheck check = golden::check_against_golden(fresh, golden, file);
    INFO(check.message);
    CHECK(check.same);
    // The golden holds every physics tick of the run (every 6th above 500 Hz): the state hash
    // proves the whole State there.
    const std::int64_t rate = scripting::Scenario::load(file, {}).model().rates.physics;
    const std::int64_t kept = rate > golden::kGoldenRowsPerSecond
                                  ? (run.physics_ticks + rate / golden::kGoldenRowsPerSecond - 1) /
                                        (rate / golden::kGoldenRowsPerSecond)
                                  : run.physics_ticks;
    CHECK(check.result.loops.at(2).loop == "physics");
    CHECK(check.result.loops.at(2).matched == kept);
  }
}

// What a golden keeps: the decimation rule of README.md, checked on a fresh trace.
TEST_CASE("a golden keeps every physics row and the servo and haptic rows at physics ticks", "[golden]") {
  const std::string file = kSource + "/scenarios/two_finger_lift.lua";
  const std::string full = kTmp + "/golden_decimate_full.h5";
  const std::string small = kTmp + "/golden_decimate_small.h5";
  const app::RunResult run = golden::run_for_golden(file, full);
  REQUIRE(run.error.empty());
  golden::decimate_trace(full, small);
  // 3000 / 50 Hz: a physics tick every 60 servo ticks, from tick 0.
  const auto servo = recordings::read_dataset(small, "/servo/tick").values;
  const auto haptic = recordings::read_dataset(small, "/haptic/tick").values;
  const auto physics = recordings::read_dataset(small, "/physics/tick").values;
  CHECK(servo.size() == static_cast<std::size_t>(run.physics_ticks));
  CHECK(servo == physics);
  CHECK(haptic == physics);
  CHECK(physics == recordings::read_dataset(full, "/physics/tick").values);
  for (double t : servo) CHECK(std::fmod(t, 60.0) == 0.0);
  // Same data where ticks meet, every golden row matched; attributes copied, plus `golden`.
  recordings::CompareOptions options;
  options.bitwise = true;
  const auto result = recordings::compare_traces(full, small, options);
  CHECK(result.same());
  for (const auto& loop : result.loops) {
    CHECK(loop.only_b == 0);
    CHECK(loop.matched == loop.rows_b);
  }
  CHECK(result.loops.at(0).only_a == run.servo_ticks - run.physics_ticks);
  CHECK(recordings::read_string_attribute(small, "/", "scenario_source") ==
        recordings::read_string_attribute(full, "/", "scenario_source"));
  CHECK(recordings::read_string_attribute(small, "/physics/objects/box/position", "units") == "m");
  CHECK(recordings::read_string_attribute(small, "/haptic", "bodies") ==
        recordings::read_string_attribute(full, "/haptic", "bodies"));
  CHECK_THAT(recordings::read_string_attribute(small, "/", "golden"), Catch::Contains("multiples of 60"));
  CHECK(fs::file_size(small) * 5 < fs::file_size(full));
}

// Above 500 Hz physics a golden keeps at most 500 physics rows per simulated second: the lift
// with every loop at 3000 Hz keeps the rows of every table at ticks that are multiples of
// 3000 / 500 = 6, i.e. 1/6 of the physics rows, all of them matched bit for bit.
TEST_CASE("a golden of a fast physics loop keeps 500 physics rows per second", "[golden]") {
  scripting::LoadOptions load;
  load.sets = {"rates.physics=3000", "rates.haptic=3000", "duration=2"};
  const auto scenario = scripting::Scenario::load(kSource + "/scenarios/two_finger_lift.lua", load);
  const std::string full = kTmp + "/golden_fast_full.h5";
  const std::string small = kTmp + "/golden_fast_small.h5";
  app::RunOptions options;
  options.out = full;
  const app::RunResult run = app::run_scenario(scenario, options);
  REQUIRE(run.error.empty());
  REQUIRE(run.physics_ticks == 6000);
  golden::decimate_trace(full, small);
  const auto physics = recordings::read_dataset(small, "/physics/tick").values;
  CHECK(physics.size() == 1000);
  for (double t : physics) CHECK(std::fmod(t, 6.0) == 0.0);
  CHECK(recordings::read_dataset(small, "/servo/tick").values == physics);
  CHECK(recordings::read_dataset(small, "/haptic/tick").values == physics);
  recordings::CompareOptions compare;
  compare.bitwise = true;
  const auto result = recordings::compare_traces(full, small, compare);
  CHECK(result.same());
  for (const auto& loop : result.loops) CHECK(loop.matched == loop.rows_b);
  CHECK_THAT(recordings::read_string_attribute(small, "/", "golden"), Catch::Contains("multiples of 6 "));
}

// The check can fail, and says where: one element of the golden moved by 1e-12 m at physics
// row 100 (tick 6000, t = 2 s) is reported there, by quantity and component, with the command
// that re-blesses and the toolchain and CPU differences that void the promise.
TEST_CASE("a golden that differs by one element is reported at its tick with the bless command", "[golden]") {
  const std::string file = kSource + "/scenarios/two_finger_lift.lua";
  const std::string golden = golden::golden_path(kGoldenDir, file);
  REQUIRE(fs::exists(golden));
  const std::string changed = kTmp + "/golden_changed.h5";
  fs::copy_file(golden, changed, fs::copy_options::overwrite_existing);
  perturb(changed, "/physics/objects/box/position", 100, 2, 1e-12);
  // As if blessed with another toolchain on another machine: the message says so.
  set_root_string(changed, "compiler", "clang 99");
  set_root_string(changed, "golden_cpu", "Some Other CPU");
  const std::string fresh = kTmp + "/golden_changed_run.h5";
  REQUIRE(golden::run_for_golden(file, fresh).error.empty());
  const golden::GoldenCheck check = golden::check_against_golden(fresh, changed, file);
  INFO(check.message);
  CHECK_FALSE(check.same);
  CHECK(check.result.differing_datasets() == 1);
  CHECK_THAT(check.message, Catch::Contains("first divergence at tick 6000 (t = 2.000000 s): "
                                            "physics/objects/box/position z"));
  CHECK_THAT(check.message, Catch::Contains("tools/bless scenarios/two_finger_lift.lua"));
  CHECK_THAT(check.message, Catch::Contains("the golden's compiler was 'clang 99'"));
  CHECK_THAT(check.message, Catch::Contains("blessed on CPU 'Some Other CPU'"));
}

// The bless command itself: a golden that matches is left alone (exit 0), --dry-run writes
// nothing, a missing scenario or an unknown option is bad input (exit 2).
TEST_CASE("tools/bless leaves a matching golden alone and refuses bad input", "[golden]") {
  const std::string bless = GRASPSIM_BLESS;
  const std::string golden = golden::golden_path(kGoldenDir, "two_finger_lift.lua");
  const auto before = fs::last_write_time(golden);
  const Outcome same = shell(bless + " --dry-run " + kSource + "/scenarios/two_finger_lift.lua");
  INFO(same.output);
  CHECK(same.status == 0);
  CHECK_THAT(same.output, Catch::Contains("unchanged: bit-identical"));
  CHECK(fs::last_write_time(golden) == before);
  const Outcome missing = shell(bless + " " + kTmp + "/nowhere.lua");
  CHECK(missing.status == 2);
  CHECK_THAT(missing.output, Catch::Contains("no such scenario file"));
  CHECK(shell(bless + " --frobnicate").status == 2);
  CHECK(shell(bless).status == 2);
}

// Determinism in one process: two runs give the same trace bit for bit and the same attributes
// (none is wall-clock), also when the rows are written in other blocks (other flush points:
// the flushes change where data lands in the file, never the data).
TEST_CASE("repeated runs in one process give bit-identical traces and attributes", "[determinism]") {
  for (const std::string name : {"pole_balance", "lift_and_place"}) {
    const auto scenario = scripting::Scenario::load(kSource + "/scenarios/" + name + ".lua", {});
    std::vector<std::string> traces;
    for (const std::size_t block_rows : {std::size_t{1024}, std::size_t{1024}, std::size_t{37}}) {
      app::RunOptions options;
      options.trace.block_rows = block_rows;
      options.out = kTmp + "/determinism_" + name + "_" + std::to_string(traces.size()) + ".h5";
      REQUIRE(app::run_scenario(scenario, options).error.empty());
      traces.push_back(options.out);
    }
    recordings::CompareOptions options;
    options.bitwise = true;
    options.attributes = true;
    options.all_ticks = true;
    for (std::size_t i = 1; i < traces.size(); ++i) {
      const auto result = recordings::compare_traces(traces[0], traces[i], options);
      INFO(name << " run " << i << ": " << golden::divergence_summary(result));
      CHECK(result.same());
      CHECK(result.attributes.empty());
    }
  }
}

// Determinism across processes: two `graspsim run` child processes, compared by `graspsim compare
// --bitwise` (and a third with --compress 4: compression changes the bytes, not the values).
TEST_CASE("two graspsim run processes give bit-identical traces", "[determinism]") {
  const std::string cli = GRASPSIM_CLI;
  const std::string scenario = kSource + "/scenarios/three_finger_rotate.lua";
  const std::string a = kTmp + "/determinism_proc_a.h5", b = kTmp + "/determinism_proc_b.h5",
                    c = kTmp + "/determinism_proc_c.h5";
  REQUIRE(shell(cli + " run --quiet " + scenario + " --out " + a).status == 0);
  REQUIRE(shell(cli + " run --quiet " + scenario + " --out " + b).status == 0);
  REQUIRE(shell(cli + " run --quiet --compress 4 " + scenario + " --out " + c).status == 0);
  const Outcome ab = shell(cli + " compare --bitwise --all-ticks --attributes " + a + " " + b);
  INFO(ab.output);
  CHECK(ab.status == 0);
  const Outcome ac = shell(cli + " compare --bitwise --all-ticks " + a + " " + c);
  INFO(ac.output);
  CHECK(ac.status == 0);
}

#ifdef GRASPSIM_CLI_TWIN
// Determinism, Debug against Release: the same source built at -O0 (Debug, Eigen's assertions on)
// and -O2 (Release), both with -ffp-contract=off, give bit-identical traces on this machine.
// The twin binary is built by tests/golden/CMakeLists.txt (ExternalProject) into build/debug.
TEST_CASE("a Debug and a Release build give bit-identical traces", "[determinism]") {
  const std::string cli = GRASPSIM_CLI, twin = GRASPSIM_CLI_TWIN;
  REQUIRE(fs::exists(twin));
  for (const std::string name : {"mesh_grasp", "lift_and_place"}) {
    const std::string scenario = kSource + "/scenarios/" + name + ".lua";
    const std::string a = kTmp + "/determinism_" + name + "_main.h5", b = kTmp + "/determinism_" + name + "_twin.h5";
    REQUIRE(shell(cli + " run --quiet " + scenario + " --out " + a).status == 0);
    REQUIRE(shell(twin + " run --quiet " + scenario + " --out " + b).status == 0);
    // The two really are different builds.
    const std::string flags_a = recordings::read_string_attribute(a, "/", "build_flags");
    const std::string flags_b = recordings::read_string_attribute(b, "/", "build_flags");
    INFO(flags_a << " | " << flags_b);
    CHECK(flags_a != flags_b);
    CHECK_THAT(flags_a + flags_b, Catch::Contains("Debug:") && Catch::Contains("Release:"));
    const Outcome o = shell(cli + " compare --bitwise --all-ticks " + a + " " + b);
    INFO(o.output);
    CHECK(o.status == 0);
  }
}
#else
// Without the twin (GRASPSIM_TWIN_BUILD=OFF, or a generator other than Makefiles) the comparison
// cannot run: ctest reports it skipped, never passed.
TEST_CASE("a Debug and a Release build give bit-identical traces", "[determinism]") {
  GRASPSIM_SKIP("the Debug twin is not built (GRASPSIM_TWIN_BUILD=OFF or a generator other than Makefiles)");
}
#endif

// Replay reproduces the golden traces: every scenario's run, replayed from its own trace (every
// finger fed from the recorded device samples instead of its script), gives a trace that
// matches the golden bit for bit at every golden row, state_hash included. (A golden itself is
// decimated, so it cannot be the replay's input: its servo rows skip ticks.)
TEST_CASE("every scenario replayed from its trace reproduces its golden", "[golden][replay]") {
  for (const std::string& file : scenario_files()) {
    const std::string golden = golden::golden_path(kGoldenDir, file);
    if (!fs::exists(golden)) continue;   // reported by the golden test above
    const std::string stem = fs::path(file).stem().string();
    const std::string recorded = kTmp + "/golden_replay_source_" + stem + ".h5";
    const std::string replayed = kTmp + "/golden_replay_" + stem + ".h5";
    INFO(file);
    const app::RunResult run = golden::run_for_golden(file, recorded);
    REQUIRE(run.error.empty());
    const app::ReplayPlan plan = app::load_replay(recorded, app::ReplayOptions{});
    const app::RunResult again = app::run_scenario(*plan.scenario, plan.run_options(replayed));
    INFO("replay error: " << again.error);
    CHECK(again.error.empty());
    CHECK(again.servo_ticks == run.servo_ticks);
    const golden::GoldenCheck check = golden::check_against_golden(replayed, golden, file);
    INFO(check.message);
    CHECK(check.same);
    fs::remove(recorded);
    fs::remove(replayed);
  }
}
