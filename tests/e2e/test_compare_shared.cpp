// `graspsim compare` of traces that hold different tables (recordings/README.md "Comparing
// traces"): a device session against its scripted run lists /devices as one-sided and compares
// the loops both hold; `--only` selects loops; the exit status keeps its meaning (0 same, 1
// different, 2 unusable input).
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "graspsim/recordings/trace_compare.hpp"
#include "tests/support/shell.hpp"

namespace {

namespace fs = std::filesystem;
namespace rec = graspsim::recordings;
using graspsim::test::Outcome;

const std::string kCli = GRASPSIM_CLI;
const std::string kLift = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/two_finger_lift.lua";
const std::string kTmp = GRASPSIM_TEST_TMP;

Outcome cli(const std::string& args) { return graspsim::test::shell(kCli + " " + args); }

// The lift into kTmp/<name>.h5 with extra run arguments; returns the path.
std::string lift(const std::string& name, const std::string& extra = "") {
  const std::string out = kTmp + "/compare_shared_" + name + ".h5";
  const Outcome o = cli("run " + kLift + " --quiet --out " + out + " " + extra);
  INFO(o.output);
  REQUIRE(o.status == 0);
  return out;
}

std::vector<std::string> loop_names(const rec::CompareResult& r) {
  std::vector<std::string> out;
  for (const auto& l : r.loops) out.push_back(l.loop);
  return out;
}

}  // namespace

TEST_CASE("a device session against its scripted run: /devices is one-sided, the loops both hold are compared",
          "[compare_shared]") {
  const std::string scripted = lift("scripted");
  // The index finger fed from the scripted run's own /servo samples (a replay device): the same
  // motion, so every loop both hold is bit for bit the scripted run's; it adds /devices/index.
  const std::string replayed = lift("replay_device", "--device index=replay:" + scripted);
  // The index finger on the simulated Phantom, held by a hand following the script: the device's
  // dynamics move the HIP off the script from the first tick, so the runs differ.
  const std::string phantom = lift("phantom", "--device index=sim-phantom");

  rec::CompareOptions bitwise;
  bitwise.bitwise = true;
  const rec::CompareResult same = rec::compare_traces(scripted, replayed, bitwise);
  CHECK(same.same());
  CHECK(loop_names(same) == std::vector<std::string>{"servo", "haptic", "physics"});
  REQUIRE(same.one_sided.size() == 1);
  CHECK(same.one_sided[0].table == "devices/index");
  CHECK_FALSE(same.one_sided[0].in_a);
  // Either way round.
  const rec::CompareResult reversed = rec::compare_traces(replayed, scripted, bitwise);
  REQUIRE(reversed.one_sided.size() == 1);
  CHECK(reversed.one_sided[0].in_a);

  // The CLI: exit 0 and the table listed as one-sided.
  const Outcome o = cli("compare --bitwise " + scripted + " " + replayed);
  INFO(o.output);
  CHECK(o.status == 0);
  CHECK_THAT(o.output, Catch::Contains("devices/index  only in B: not compared") && Catch::Contains("SAME: bitwise"));
  const Outcome j = cli("compare --json " + scripted + " " + replayed);
  CHECK(j.status == 0);
  CHECK_THAT(j.output, Catch::Contains("\"one_sided_tables\": [{\"table\": \"devices/index\", \"in\": \"b\"}]"));

  // The Phantom session: compared (exit 1, different), not refused (exit 2); the first
  // difference is the index finger's HIP at servo tick 1, the first tick the device's dynamics act.
  const rec::CompareResult differ = rec::compare_traces(scripted, phantom);
  CHECK_FALSE(differ.same());
  CHECK(loop_names(differ) == std::vector<std::string>{"servo", "haptic", "physics"});
  REQUIRE(differ.one_sided.size() == 1);
  CHECK(differ.one_sided[0].table == "devices/index");
  REQUIRE(differ.datasets.front().first);
  CHECK(differ.datasets.front().path == "servo/fingers/index/hip");
  const Outcome p = cli("compare " + scripted + " " + phantom);
  INFO(p.output);
  CHECK(p.status == 1);
  CHECK_THAT(p.output, Catch::Contains("devices/index  only in B: not compared") && Catch::Contains("DIFFERENT"));
}

TEST_CASE("compare --only selects the loops compared, and the rest are neither compared nor listed", "[compare_shared]") {
  const std::string scripted = lift("only_a");
  const std::string phantom = lift("only_phantom", "--device index=sim-phantom");
  const std::string physics5 = lift("only_physics5", "--record physics:5");

  rec::CompareOptions only;
  only.only = {"physics"};
  const rec::CompareResult p = rec::compare_traces(scripted, phantom, only);
  CHECK(loop_names(p) == std::vector<std::string>{"physics"});
  CHECK(p.one_sided.empty());   // /devices is not selected, so not listed
  for (const auto& d : p.datasets) CHECK(d.loop == "physics");
  // Two loops, as one comma list on the command line.
  const Outcome two = cli("compare --json --only servo,physics " + scripted + " " + phantom);
  CHECK(two.status == 1);
  CHECK_THAT(two.output, Catch::Contains("\"only\": [\"servo\", \"physics\"]"));
  CHECK_THAT(two.output, !Catch::Contains("\"loop\": \"haptic\""));
  // "devices" selects every /devices/<finger> table: a table one trace holds only, so nothing
  // is left to compare: unusable, exit 2.
  const Outcome devices = cli("compare --only devices " + scripted + " " + phantom);
  INFO(devices.output);
  CHECK(devices.status == 2);
  CHECK_THAT(devices.output, Catch::Contains("share no selected loop"));

  // A decimated trace against the full one: only the ticks both hold are compared, and they are
  // equal (exit 0); --all-ticks counts the 160 physics ticks only the full trace holds (exit 1).
  const Outcome shared = cli("compare " + scripted + " " + physics5);
  INFO(shared.output);
  CHECK(shared.status == 0);
  CHECK_THAT(shared.output, Catch::Contains("servo      only in A: not compared"));
  const Outcome all = cli("compare --all-ticks " + scripted + " " + physics5);
  CHECK(all.status == 1);
  CHECK_THAT(all.output, Catch::Contains("160 ticks are in one trace only"));
}

TEST_CASE("compare refuses loops it cannot compare with exit 2", "[compare_shared][bad_input]") {
  const std::string physics = lift("refuse_physics", "--record physics");
  const std::string servo = lift("refuse_servo", "--record servo");
  struct Case {
    std::string args, says;
  };
  const std::vector<Case> cases = {
      {"compare " + physics + " " + servo, "share no loop to compare"},
      {"compare --only foo " + physics + " " + physics, "--only foo: neither trace has a loop 'foo'"},
      {"compare --only physics, " + physics + " " + physics, "an empty loop name"},
      {"compare --only " + physics + " " + physics, "compare needs two trace files"},
      {"compare --only servo " + physics + " " + servo, "share no selected loop"},
  };
  for (const Case& c : cases) {
    const Outcome o = cli(c.args);
    INFO("graspsim " << c.args << "\n" << o.output);
    CHECK(o.status == 2);
    CHECK_THAT(o.output, Catch::Contains(c.says));
  }
  const Outcome help = cli("compare --help");
  CHECK_THAT(help.output, Catch::Contains("--only LOOP") && Catch::Contains("only in A") &&
                              Catch::Contains("0 same") && Catch::Contains("1 different") &&
                              Catch::Contains("2 unusable input"));
}
