// Perturbed waypoints from the command line (`graspsim run S.lua --jitter A --jitter-seed N`,
// README.md "Perturbed waypoints"): the finger starts where its first waypoint plus the recorded
// offset puts it, the same seed gives the same trace bit for bit, and `graspsim replay` of a
// jittered run (scripted, a feedback controller, a simulated Phantom) reproduces it bit for bit.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "graspsim/recordings/trace_reader.hpp"
#include "tests/support/shell.hpp"

namespace {

const std::string kCli = GRASPSIM_CLI;
const std::string kScenarios = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/";
const std::string kTmp = GRASPSIM_TEST_TMP;

using graspsim::test::Outcome;

Outcome cli(const std::string& args) { return graspsim::test::shell(kCli + " " + args); }

// The offset of one line of the trace's `jitter_offsets` ("thumb waypoint 1: dx dy dz").
std::vector<double> offset_of(const std::string& trace, const std::string& prefix) {
  std::istringstream lines(graspsim::recordings::read_string_attribute(trace, "/", "jitter_offsets"));
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(prefix, 0) != 0) continue;
    std::istringstream numbers(line.substr(prefix.size()));
    std::vector<double> v(3);
    numbers >> v[0] >> v[1] >> v[2];
    return v;
  }
  FAIL("no line '" << prefix << "' in jitter_offsets");
  return {};
}

std::vector<double> row(const std::string& trace, const std::string& dataset, std::size_t n) {
  const graspsim::recordings::Dataset d = graspsim::recordings::read_dataset(trace, dataset);
  return {d.values.at(3 * n), d.values.at(3 * n + 1), d.values.at(3 * n + 2)};
}

}  // namespace

// The lift's thumb starts at its first waypoint (held before t = 0's segment), so its HIP at
// servo tick 0 is that waypoint plus the recorded offset: the difference from the plain run's is
// the offset up to one rounding of a coordinate of about 0.1 m (ulp 1.4e-17 m; 1e-16 m allowed).
TEST_CASE("graspsim run --jitter moves the waypoints by the recorded offsets, and the same seed gives the same trace",
          "[e2e][cli][jitter]") {
  const std::string plain = kTmp + "/jitter_plain.h5", a = kTmp + "/jitter_a.h5", b = kTmp + "/jitter_b.h5",
                    other = kTmp + "/jitter_other.h5";
  const std::string lift = kScenarios + "two_finger_lift.lua --quiet";
  REQUIRE(cli("run " + lift + " --out " + plain).status == 0);
  const Outcome o = cli("run " + lift + " --jitter 0.5e-3 --jitter-seed 7 --out " + a);
  INFO(o.output);
  REQUIRE(o.status <= 1);   // ran; whether the lift's expectations hold is test_robustness's
  CHECK(graspsim::recordings::read_double_attribute(a, "/", "jitter_amplitude") == 0.5e-3);
  CHECK(graspsim::recordings::read_int_attribute(a, "/", "jitter_seed") == 7);
  CHECK_FALSE(graspsim::recordings::has_attribute(plain, "/", "jitter_amplitude"));
  for (const char* finger : {"thumb", "index"}) {
    const std::vector<double> offset = offset_of(a, std::string(finger) + " waypoint 1: ");
    const std::vector<double> hip = row(a, std::string("/servo/fingers/") + finger + "/hip", 0);
    const std::vector<double> hip0 = row(plain, std::string("/servo/fingers/") + finger + "/hip", 0);
    for (int i = 0; i < 3; ++i) {
      INFO(finger << " axis " << i << ": offset " << offset[i] << " m, hip moved " << hip[i] - hip0[i] << " m");
      CHECK(std::abs(offset[i]) <= 0.5e-3);
      CHECK(std::abs((hip[i] - hip0[i]) - offset[i]) <= 1e-16);
    }
  }
  REQUIRE(cli("run " + lift + " --jitter 0.5e-3 --jitter-seed 7 --out " + b).status <= 1);
  CHECK(cli("compare --bitwise " + a + " " + b).status == 0);
  REQUIRE(cli("run " + lift + " --jitter 0.5e-3 --jitter-seed 8 --out " + other).status <= 1);
  CHECK(cli("compare --bitwise " + a + " " + other).status == 1);
}

// Replay feeds every finger from its recorded samples and loads the scenario with the recorded
// jitter again, so the scripts that run alongside (pole_balance's controller reads the view) and
// a simulated Phantom's recorded device rows give the run again, bit for bit.
TEST_CASE("graspsim replay of a jittered run reproduces it bit for bit", "[e2e][cli][jitter][replay]") {
  struct Case { std::string scenario, extra, name; };
  for (const Case& c : {Case{"gravity_drop", "", "scripted"}, Case{"pole_balance", "", "function"},
                        Case{"two_finger_lift", " --device thumb=sim-phantom", "sim_phantom"}}) {
    const std::string trace = kTmp + "/jitter_replay_" + c.name + ".h5";
    const Outcome run = cli("run " + kScenarios + c.scenario + ".lua --quiet --jitter 0.5e-3 --jitter-seed 3" + c.extra +
                            " --out " + trace);
    INFO(c.scenario << c.extra << ": " << run.output);
    REQUIRE(run.status <= 1);
    const Outcome replay = cli("replay " + trace + " --out " + kTmp + "/jitter_replay_" + c.name + ".replay.h5");
    INFO(replay.output);
    CHECK_THAT(replay.output, Catch::Contains("reproduced  bit for bit"));
    CHECK_THAT(replay.output, !Catch::Contains("jitter offsets drawn again"));
    CHECK(replay.status == run.status);
  }
}

TEST_CASE("graspsim run refuses a bad jitter with exit status 2", "[e2e][cli][jitter][bad_input]") {
  const std::string run = "run " + kScenarios + "gravity_drop.lua --out " + kTmp + "/jitter_bad.h5 ";
  struct Case { std::string args, says; };
  for (const Case& c : {Case{"--jitter -1e-3", "--jitter needs an amplitude in m, a number >= 0"},
                        Case{"--jitter abc", "--jitter needs an amplitude"}, Case{"--jitter", "--jitter needs"},
                        Case{"--jitter-seed 3", "--jitter-seed needs --jitter A with A > 0"},
                        Case{"--jitter 1e-3 --jitter-seed 1.5", "--jitter-seed needs an integer from 0 to 2^63 - 1"},
                        Case{"--jitter 1e-3 --jitter-seed -3", "--jitter-seed needs an integer"},
                        Case{"--jitter 1e-3 --jitter-seed 9223372036854775808", "--jitter-seed needs an integer"}}) {
    const Outcome o = cli(run + c.args);
    INFO("graspsim " << run << c.args << "\n" << o.output);
    CHECK(o.status == 2);
    CHECK_THAT(o.output, Catch::Contains(c.says));
  }
}
