// Perturbed waypoints from the command line (`graspsim run S.lua --jitter A --jitter-seed N`,
// README.md "Perturbed waypoints"): the finger starts where its first waypoint plus the recorded
// offset puts it, the same seed gives the same trace bit for bit, and `graspsim replay` of a
// jittered run (scripted, a feedback controller, a simulated Phantom) reproduces it bit for bit.
#include <catch2/catch.hpp>

#include <algorithm>
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

// A fast top pushed off its finger by 2 mm of jitter (gyro_precession, seed 7001: the pivot
// starts off the top's axis and the top slides off) tumbles away free, spinning at 100 rad/s
// (2 rad a physics step at 500 Hz). Its torque-free step conserves its kinetic energy and |L|
// (integrate.hpp, gyroscopic_change; the law is tests/engine/test_free_spin.cpp), so the energy
// watch, which stops a run whose untouched bodies gain energy, has nothing to stop: the run ends,
// exit 1 (the top no longer stays on the finger, as the scenario expects), not exit 2 "gained
// ... J with no finger on it ... the integration is unstable". From the first physics row with
// no finger on the top until it lands on the floor, its rotational energy 1/2 w_b.J w_b does not
// rise (gravity, at the centre of mass, changes no spin), within 1e-9 relative (rounding over a
// few hundred steps, the trace's 17 digits).
TEST_CASE("a fast top that leaves its finger tumbles away, and the energy watch does not stop the run", "[jitter][free_spin]") {
  const std::string trace = kTmp + "/jitter_top_free.h5";
  const Outcome o = cli("run " + kScenarios + "gyro_precession.lua --jitter 2e-3 --jitter-seed 7001 --out " + trace);
  INFO(o.output);
  CHECK(o.status == 1);
  CHECK_THAT(o.output, Catch::Contains("FAIL  the top stays on the finger"));
  CHECK_THAT(o.output, !Catch::Contains("unstable") && !Catch::Contains("with no finger on it"));
  const auto touching = graspsim::recordings::read_dataset(trace, "/haptic/fingers/pivot/body").values;
  const auto w = graspsim::recordings::read_dataset(trace, "/physics/objects/top/angular_velocity").values;
  const auto q = graspsim::recordings::read_dataset(trace, "/physics/objects/top/quaternion").values;
  const auto physics_tick = graspsim::recordings::read_dataset(trace, "/physics/tick").values;
  const auto floor = graspsim::recordings::read_dataset(trace, "/physics/objects/top/floor_contacts").values;
  const auto haptic_tick = graspsim::recordings::read_dataset(trace, "/haptic/tick").values;
  // The last haptic tick at which the pivot touched the top (body index 0); free after it.
  double left_at = -1.0;
  for (std::size_t i = 0; i < touching.size(); ++i)
    if (touching[i] == 0.0) left_at = haptic_tick[i];
  REQUIRE(left_at >= 0.0);
  const double a = 0.05, h = 0.02, m = 1.0;          // the scenario's top: half sizes (a, a, h), kg
  const double j[3] = {m / 3 * (a * a + h * h), m / 3 * (a * a + h * h), m / 3 * (2 * a * a)};
  double e_free = -1.0, largest_rise = 0.0;
  int free_rows = 0;
  for (std::size_t r = 0; r < physics_tick.size(); ++r) {
    if (physics_tick[r] <= left_at + 6.0) continue;   // a haptic tick after it, so no push is in this step
    if (floor[r] > 0.0) break;                         // free until it lands
    // w_b = R^T w, R from the unit quaternion (w, x, y, z).
    const double qw = q[4 * r], qx = q[4 * r + 1], qy = q[4 * r + 2], qz = q[4 * r + 3];
    const double R[3][3] = {{1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)},
                            {2 * (qx * qy + qw * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qw * qx)},
                            {2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)}};
    double e = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double wb = R[0][i] * w[3 * r] + R[1][i] * w[3 * r + 1] + R[2][i] * w[3 * r + 2];
      e += 0.5 * j[i] * wb * wb;
    }
    if (e_free < 0.0) e_free = e;
    ++free_rows;
    largest_rise = std::max(largest_rise, (e - e_free) / e_free);
  }
  INFO("rotational energy when free " << e_free << " J, largest rise " << largest_rise << " over " << free_rows
                                      << " physics rows");
  CHECK(free_rows >= 10);
  REQUIRE(e_free > 0.5);   // 1/2 I3 w3^2 = 0.83 J at 100 rad/s: it still spins fast
  CHECK(largest_rise <= 1e-9);
}
