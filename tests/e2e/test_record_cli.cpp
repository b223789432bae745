// Recording choices as a user meets them (README.md "What a run prints and writes"): `--record
// LOOP[:EVERY],...` keeps exactly the chosen loops at every EVERY-th tick of each and says so in
// the root attribute `record`; `--no-trace` writes nothing and changes nothing else; bad values
// are refused with the flag named, exit 2, nothing written; replay refuses a trace that does not
// hold every servo tick.
#include <catch2/catch.hpp>

#include <cstdint>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "graspsim/recordings/record_selection.hpp"
#include "graspsim/recordings/trace_compare.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "tests/support/shell.hpp"

namespace {

namespace fs = std::filesystem;
namespace rec = graspsim::recordings;
using graspsim::test::Outcome;

const std::string kCli = GRASPSIM_CLI;
const std::string kLift = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/two_finger_lift.lua";
const std::string kTmp = GRASPSIM_TEST_TMP;

// The lift: 4 s at 3000 / 500 / 50 Hz, so 12000 servo, 2000 haptic and 200 physics ticks;
// physics runs at every 60th servo tick from tick 0.
constexpr std::int64_t kServoTicks = 12000, kPhysicsTicks = 200, kPhysicsDivisor = 60;

// A fresh empty directory under the test tmp.
std::string fresh_dir(const std::string& name) {
  const std::string dir = kTmp + "/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// graspsim run of the lift from `dir` (so a default-named trace would land there).
Outcome run_in(const std::string& dir, const std::string& args) {
  return graspsim::test::shell("cd " + dir + " && " + kCli + " run " + kLift + " " + args);
}

std::set<std::string> listing(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// The expectation lines ("PASS ..." / "FAIL ...") a run printed, in order.
std::vector<std::string> expectation_lines(const std::string& output) {
  std::vector<std::string> lines;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);)
    if (line.find("PASS  ") != std::string::npos || line.find("FAIL  ") != std::string::npos) lines.push_back(line);
  return lines;
}

std::vector<double> ticks(const std::string& trace, const std::string& table) {
  return rec::read_dataset(trace, "/" + table + "/tick").values;
}

}  // namespace

TEST_CASE("a --record argument parses to its loops and strides and prints back the same", "[record]") {
  // text() is the attribute and a valid --record argument: parse(text()) is the identity.
  const rec::RecordSelection s = rec::RecordSelection::parse("physics,servo:10");
  CHECK(s.of(rec::RecordedLoop::kServo) == 10);
  CHECK(s.of(rec::RecordedLoop::kHaptic) == 0);
  CHECK(s.of(rec::RecordedLoop::kPhysics) == 1);
  CHECK(s.of(rec::RecordedLoop::kDevices) == 0);
  CHECK(s.text() == "servo:10,physics:1");
  CHECK(rec::RecordSelection::parse(s.text()).every == s.every);
  CHECK(rec::RecordSelection{}.everything());
  CHECK(rec::RecordSelection{}.text() == "servo:1,haptic:1,physics:1,devices:1");   // no contacts
  CHECK(rec::RecordSelection::parse("physics,contacts:2").text() == "physics:1,contacts:2");
  // A trace without the attribute was written before it: every loop at every tick.
  CHECK(rec::RecordSelection::from_attribute(std::nullopt).everything());
  for (const char* bad : {"", "foo", "physics:0", "physics:-1", "physics:x", "physics:", "physics,physics", ",",
                          "physics,", "servo:1.5"}) {
    INFO(bad);
    CHECK_THROWS_AS(rec::RecordSelection::parse(bad), std::invalid_argument);
  }
}

TEST_CASE("a run with --record LOOP:EVERY keeps exactly every EVERY-th tick of that loop and no other loop", "[record]") {
  const std::string dir = fresh_dir("record_every");
  const std::string full = dir + "/full.h5";
  REQUIRE(run_in(dir, "--quiet --out " + full).status == 0);
  const std::vector<double> all_physics = ticks(full, "physics");
  REQUIRE(static_cast<std::int64_t>(all_physics.size()) == kPhysicsTicks);

  // Law: a loop of n ticks recorded every E-th tick from its first keeps the ticks of index
  // k E, k = 0 .. ceil(n / E) - 1: ceil(200 / E) physics rows at servo ticks k E 60. Exact
  // integers, no tolerance. Swept over E, including 1 (all), a divisor of 200 and two that
  // are not (the last kept tick is then not the last tick).
  for (const std::int64_t every : {1, 3, 5, 7, 200, 1000}) {
    INFO("--record physics:" << every);
    const std::string out = dir + "/physics_" + std::to_string(every) + ".h5";
    const Outcome o = run_in(dir, "--quiet --record physics:" + std::to_string(every) + " --out " + out);
    INFO(o.output);
    REQUIRE(o.status == 0);
    const std::vector<double> kept = ticks(out, "physics");
    const std::int64_t expected_rows = (kPhysicsTicks + every - 1) / every;
    CHECK(static_cast<std::int64_t>(kept.size()) == expected_rows);
    for (std::size_t k = 0; k < kept.size(); ++k) {
      CHECK(kept[k] == static_cast<double>(static_cast<std::int64_t>(k) * every * kPhysicsDivisor));
      CHECK(kept[k] == all_physics[k * static_cast<std::size_t>(every)]);
    }
    // No other loop.
    for (const char* absent : {"/servo", "/haptic", "/devices"}) CHECK_FALSE(rec::has_object(out, absent));
    CHECK(rec::read_string_attribute(out, "/", "record") == "physics:" + std::to_string(every));
    // The rows kept are the full run's rows at those ticks, bit for bit.
    rec::CompareOptions bitwise;
    bitwise.bitwise = true;
    const rec::CompareResult c = rec::compare_traces(full, out, bitwise);
    CHECK(c.same());
    REQUIRE(c.loops.size() == 1);
    CHECK(c.loops[0].matched == expected_rows);
    CHECK(c.loops[0].only_a == kPhysicsTicks - expected_rows);
    CHECK(c.loops[0].only_b == 0);
  }
  // Two loops, one decimated: servo:10 keeps servo ticks 0, 10, ... (1200 rows), physics all.
  const std::string two = dir + "/servo10.h5";
  REQUIRE(run_in(dir, "--quiet --record physics,servo:10 --out " + two).status == 0);
  const std::vector<double> servo = ticks(two, "servo");
  CHECK(static_cast<std::int64_t>(servo.size()) == kServoTicks / 10);
  CHECK(servo.back() == static_cast<double>(kServoTicks - 10));
  CHECK(static_cast<std::int64_t>(ticks(two, "physics").size()) == kPhysicsTicks);
  CHECK_FALSE(rec::has_object(two, "/haptic"));
  CHECK(rec::read_string_attribute(two, "/", "record") == "servo:10,physics:1");
  // The default records everything, and says so.
  CHECK(rec::read_string_attribute(full, "/", "record") == "servo:1,haptic:1,physics:1,devices:1");
  CHECK(static_cast<std::int64_t>(ticks(full, "servo").size()) == kServoTicks);
}

// /contacts: a row per floor or body-body point of every physics tick, as many per tick as the
// /physics counts of the box (floor_contacts + body_contacts: the same points; the lift has no
// sleep, so no point is left out), ticks never decreasing; compare aligns the k-th row of a
// tick with the k-th (a trace against itself: every row matched, the same) and lists the table
// as one-sided against a trace without it, still the same.
TEST_CASE("a run recording contacts writes one row per contact point and compare aligns them", "[record]") {
  const std::string dir = fresh_dir("record_contacts");
  const std::string with = dir + "/with.h5", without = dir + "/without.h5";
  REQUIRE(run_in(dir, "--quiet --record physics,contacts --out " + with).status == 0);
  REQUIRE(run_in(dir, "--quiet --record physics --out " + without).status == 0);
  const std::vector<double> physics = ticks(with, "physics");
  const std::vector<double> contact_ticks = ticks(with, "contacts");
  const std::vector<double> floor = rec::read_dataset(with, "/physics/objects/box/floor_contacts").values;
  const std::vector<double> body = rec::read_dataset(with, "/physics/objects/box/body_contacts").values;
  REQUIRE(physics.size() == static_cast<std::size_t>(kPhysicsTicks));
  std::size_t row = 0, expected = 0;
  for (std::size_t k = 0; k < physics.size(); ++k) {
    std::size_t here = 0;
    while (row < contact_ticks.size() && contact_ticks[row] == physics[k]) ++row, ++here;
    INFO("physics tick " << physics[k]);
    CHECK(here == static_cast<std::size_t>(floor[k] + body[k]));
    expected += here;
  }
  CHECK(row == contact_ticks.size());   // every row at a physics tick, in tick order
  CHECK(expected > 4);                  // the box stood on its four corners before the lift
  const rec::CompareResult self = rec::compare_traces(with, with, {});
  CHECK(self.same());
  bool aligned = false;
  for (const rec::LoopAlignment& l : self.loops)
    if (l.loop == "contacts") aligned = l.matched == static_cast<std::int64_t>(contact_ticks.size()) && l.only_a == 0;
  CHECK(aligned);
  const rec::CompareResult one_sided = rec::compare_traces(with, without, {});
  CHECK(one_sided.same());
  REQUIRE(one_sided.one_sided.size() == 1);
  CHECK(one_sided.one_sided[0].table == "contacts");
}

TEST_CASE("a run with --record devices:EVERY decimates a device session's /devices table", "[record]") {
  const std::string dir = fresh_dir("record_devices");
  const std::string out = dir + "/phantom.h5";
  const Outcome o = run_in(dir, "--quiet --device index=sim-phantom --record servo,devices:4 --out " + out);
  INFO(o.output);
  REQUIRE(o.status == 0);
  // One row per 4th servo tick: ceil(12000 / 4) = 3000 rows, ticks 0, 4, 8, ...
  const std::vector<double> device_ticks = ticks(out, "devices/index");
  CHECK(static_cast<std::int64_t>(device_ticks.size()) == kServoTicks / 4);
  CHECK(device_ticks[1] == 4.0);
  CHECK(static_cast<std::int64_t>(ticks(out, "servo").size()) == kServoTicks);
  // Replay needs every servo tick of /devices too.
  const Outcome r = graspsim::test::shell("cd " + dir + " && " + kCli + " replay " + out);
  INFO(r.output);
  CHECK(r.status == 2);
  CHECK_THAT(r.output, Catch::Contains("keeps /devices only every 4th tick"));
  CHECK_FALSE(fs::exists(dir + "/phantom.replay.h5"));
}

TEST_CASE("a run with --no-trace writes nothing and gives the traced run's expectations and exit status", "[record]") {
  // Swept over a passing run (exit 0) and a failing one (mu = 0.2: the box slides out, exit 1).
  for (const std::string set : {"", "--set mu=0.2"}) {
    INFO("graspsim run two_finger_lift " << set);
    const std::string traced_dir = fresh_dir("no_trace_traced");
    const Outcome traced = run_in(traced_dir, set);
    const std::string dir = fresh_dir("no_trace");
    const Outcome untraced = run_in(dir, set + " --no-trace");
    INFO(untraced.output);
    CHECK(listing(dir).empty());   // no trace, no .partial, no lock
    CHECK(listing(traced_dir) == std::set<std::string>{"two_finger_lift.h5"});   // the control: a traced run writes
    CHECK(untraced.status == traced.status);
    CHECK(expectation_lines(untraced.output) == expectation_lines(traced.output));
    CHECK_FALSE(expectation_lines(untraced.output).empty());
    CHECK_THAT(untraced.output, Catch::Contains("trace       none (--no-trace)"));
  }
  // An existing file at the default name is left as it was.
  const std::string dir = fresh_dir("no_trace_existing");
  graspsim::test::shell("printf keep > " + dir + "/two_finger_lift.h5");
  REQUIRE(run_in(dir, "--quiet --no-trace").status == 0);
  CHECK(listing(dir) == std::set<std::string>{"two_finger_lift.h5"});
  CHECK(fs::file_size(dir + "/two_finger_lift.h5") == 4);
}

TEST_CASE("bad recording choices are refused with the flag named, exit 2, nothing written", "[record][bad_input]") {
  struct Case {
    std::string args, says;
  };
  const std::vector<Case> cases = {
      {"--record foo", "--record foo: names an unknown loop 'foo'"},
      {"--record physics:0", "EVERY must be a whole number from 1 to 1000000000"},
      {"--record physics:-3", "EVERY must be a whole number from 1 to 1000000000"},
      {"--record physics:1000000001", "EVERY must be a whole number from 1 to 1000000000"},
      {"--record physics:999999999999999999", "EVERY must be a whole number from 1 to 1000000000"},
      {"--record physics --record servo", "--record given twice"},
      {"--record physics,physics:2", "names loop 'physics' twice"},
      {"--record physics,", "--record physics,: has an empty item"},
      {"--record", "--record needs LOOP[:EVERY]"},
      {"--no-trace --record physics", "--no-trace writes no trace, so it takes no --record"},
      {"--record physics --no-trace", "--no-trace writes no trace, so it takes no --record"},
      {"--no-trace --out x.h5", "--no-trace writes no trace, so it takes no --out"},
      {"--no-trace --compress 3", "--no-trace writes no trace, so it takes no --compress"},
  };
  for (const Case& c : cases) {
    const std::string dir = fresh_dir("record_refused");
    const Outcome o = run_in(dir, c.args);
    INFO("graspsim run two_finger_lift " << c.args << "\n" << o.output);
    CHECK(o.status == 2);
    CHECK_THAT(o.output, Catch::Contains(c.says));
    CHECK(listing(dir).empty());
  }
}

TEST_CASE("replay refuses a trace without every servo tick, and replays a decimated physics loop", "[record][replay]") {
  const std::string dir = fresh_dir("record_replay");
  struct Case {
    std::string record, says;
  };
  for (const Case& c : {Case{"physics", "which holds no /servo"}, Case{"servo:10,physics", "keeps /servo only every 10th tick"}}) {
    const std::string trace = dir + "/refused.h5";
    REQUIRE(run_in(dir, "--quiet --record " + c.record + " --out " + trace).status == 0);
    const Outcome o = graspsim::test::shell("cd " + dir + " && " + kCli + " replay " + trace + " --out again.h5");
    INFO(o.output);
    CHECK(o.status == 2);
    CHECK_THAT(o.output, Catch::Contains(c.says) && Catch::Contains("a replay needs every servo tick"));
    CHECK_FALSE(fs::exists(dir + "/again.h5"));
    // A finger fed from it in another run is refused the same way, before anything is written.
    const Outcome d = run_in(dir, "--device index=replay:" + trace + " --out device.h5");
    CHECK(d.status == 2);
    CHECK_THAT(d.output, Catch::Contains(c.says));
    CHECK_FALSE(fs::exists(dir + "/device.h5"));
  }
  // Every servo tick and every other physics tick: replayable, recorded alike, bit for bit.
  const std::string trace = dir + "/servo_physics2.h5";
  REQUIRE(run_in(dir, "--quiet --record servo,physics:2 --out " + trace).status == 0);
  const Outcome o = graspsim::test::shell("cd " + dir + " && " + kCli + " replay " + trace + " --out again.h5");
  INFO(o.output);
  CHECK(o.status == 0);
  // 200 / 2 = 100 physics ticks, each state_hash equal.
  CHECK_THAT(o.output, Catch::Contains("state_hash equal at all 100 physics ticks"));
  CHECK(rec::read_string_attribute(dir + "/again.h5", "/", "record") == "servo:1,physics:2");
}
