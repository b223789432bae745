// What a loaded scenario does during a run: finger trajectories (waypoints or Lua functions of
// time) and expectations (Lua checks of a snapshot).
#include <chrono>
#include <cmath>
#include <string>

#include <catch2/catch.hpp>

#include "graspsim/scripting/scenario.hpp"
#include "scenario_files.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;
using graspsim::Vec3;
using graspsim::scripting::ObjectSnapshot;
using graspsim::scripting::Scenario;
using graspsim::scripting::Snapshot;
using scripting_test::data_path;
using scripting_test::error_of;
using scripting_test::line_of;

namespace {

// A snapshot with the box at height z and the thumb touching it.
Snapshot snapshot(double time, double z) {
  Snapshot s;
  s.time = time;
  ObjectSnapshot box;
  box.name = "box";
  box.position = Vec3(0, 0, z);
  s.objects.push_back(box);
  graspsim::scripting::FingerSnapshot thumb;
  thumb.name = "thumb";
  thumb.touching = "box";
  thumb.force = Vec3(2, 0, 0);
  thumb.slip = 0.001;
  s.fingers.push_back(thumb);
  return s;
}

}  // namespace

// The waypoints reach hw::WaypointTrajectory as written: it holds the first position before the
// first waypoint and the last after the last, and passes through every waypoint. At the middle
// of a segment both linear and minimum-jerk (s(1/2) = 1/2) give the midpoint.
TEST_CASE("waypoint trajectories pass through their waypoints and hold before and after",
          "[scenario][trajectory]") {
  const Scenario s = Scenario::load(data_path("valid.lua"));
  auto thumb = s.make_trajectory(0);   // minjerk (the default)
  CHECK(thumb->position(-1.0) == Vec3(-0.1, 0, 0.02));
  CHECK(thumb->position(0.0) == Vec3(-0.1, 0, 0.02));
  CHECK(thumb->position(1.0) == Vec3(-0.03, 0, 0.02));
  CHECK(thumb->position(9.0) == Vec3(-0.03, 0, 0.02));
  CHECK(thumb->position(0.5).x() == Approx(-0.065).epsilon(1e-12));
  auto index = s.make_trajectory(1);   // linear
  CHECK(index->position(1.0) == Vec3(0.03, 0, 0.02));
  CHECK(index->position(1.5).z() == Approx(0.06).epsilon(1e-12));
  CHECK(index->position(1.25).z() == Approx(0.04).epsilon(1e-12));   // linear: a quarter of the way
}

TEST_CASE("a Lua function trajectory returns its positions, as x, y, z or as {x, y, z}",
          "[scenario][trajectory]") {
  const Scenario s = Scenario::load(data_path("functions.lua"));
  auto thumb = s.make_trajectory(0);
  for (double t : {0.0, 0.25, 1.0, 2.999}) {
    CHECK(thumb->position(t) == Vec3(0.1 * std::cos(t), 0.1 * std::sin(t), 0.04));
  }
  auto index = s.make_trajectory(1);
  CHECK(index->position(0.5) == Vec3(0.5, 1.0, 0.5));
}

TEST_CASE("an error inside a trajectory function reports file:line, the finger and the time",
          "[scenario][trajectory]") {
  const Scenario s = Scenario::load(data_path("functions.lua"));
  auto ring = s.make_trajectory(2);
  CHECK(ring->position(0.5) == Vec3(0, 0, 0.5));
  const std::string path = data_path("functions.lua");
  const int line = line_of(path, "TRAJECTORY ERROR");
  const std::string message = error_of([&] { ring->position(1.5); });
  CHECK_THAT(message, StartsWith(path + ":" + std::to_string(line) +
                                 ": the ring finger only moves for 1 s (fingers[3] 'ring' "
                                 "trajectory at t = 1.5 s)\nstack traceback:"));
  CHECK(ring->position(0.25) == Vec3(0, 0, 0.25));   // the state is usable after an error
}

TEST_CASE("a trajectory function that returns no finite x, y, z is an error naming finger and time",
          "[scenario][trajectory]") {
  const Scenario s = Scenario::load(data_path("functions.lua"));
  const std::string path = data_path("functions.lua");
  auto pinky = s.make_trajectory(3);
  CHECK(error_of([&] { pinky->position(0.5); }) ==
        path + ": fingers[4] 'pinky' trajectory at t = 0.5 s: the function must return x, y, z (m) "
               "and optionally the gimbal pitch (rad), or {x, y, z[, pitch]}, but returned "
               "(string, number, number)");
  CHECK(error_of([&] { pinky->position(1.5); }) ==
        path + ": fingers[4] 'pinky' trajectory at t = 1.5 s: the function returned a non-finite "
               "position (nan, 0, 0)");
  CHECK_THAT(error_of([&] { pinky->position(2.5); }),
             Contains("but returned a table that is not {x, y, z} or {x, y, z, pitch} (2 elements)"));
}

TEST_CASE("an endless loop in a trajectory function stops with the per-call budget message",
          "[scenario][trajectory]") {
  graspsim::scripting::LoadOptions options;
  options.limits.call_instructions = 1'000'000;
  const Scenario s = Scenario::load(data_path("functions.lua"), options);
  auto stuck = s.make_trajectory(5);
  const auto start = std::chrono::steady_clock::now();
  CHECK_THAT(error_of([&] { stuck->position(0.0); }),
             Contains("instruction budget of 1000000 instructions exceeded (an endless loop?) "
                      "(fingers[6] 'stuck' trajectory at t = 0 s)"));
  CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < 1.0);
}

TEST_CASE("an expectation passes or fails with its message, and sees now and initial",
          "[scenario][expect]") {
  const Scenario s = Scenario::load(data_path("functions.lua"));
  REQUIRE(s.expectations().size() == 4);
  CHECK(s.expectations()[0].at == 2.5);
  CHECK(s.expectations()[1].at < 0.0);   // at the end of the run
  const Snapshot initial = snapshot(0.0, 0.04);
  const auto lifted = s.check(0, snapshot(2.5, 0.10), initial);
  CHECK(lifted.what == "box lifted at least 5 cm");
  CHECK(lifted.passed);
  CHECK(lifted.detail == "z = 0.100 m");
  const auto dropped = s.check(0, snapshot(2.5, 0.05), initial);
  CHECK_FALSE(dropped.passed);
  CHECK(dropped.detail == "z = 0.050 m");
  const auto touching = s.check(2, snapshot(1.0, 0.04), initial);
  CHECK(touching.passed);
  CHECK(touching.detail == "box");
}

TEST_CASE("a check that does not return a boolean, or fails, is an error naming the expectation",
          "[scenario][expect]") {
  const Scenario s = Scenario::load(data_path("functions.lua"));
  const std::string path = data_path("functions.lua");
  const Snapshot now = snapshot(3.0, 0.04);
  CHECK(error_of([&] { s.check(1, now, now); }) ==
        path + ": expect[2] 'forgets to return': check must return a boolean, got nil");
  const int line = line_of(path, "CHECK ERROR");
  CHECK_THAT(error_of([&] { s.check(3, now, now); }),
             StartsWith(path + ":" + std::to_string(line) + ": attempt to index a nil value") &&
             Contains("(expect[4] 'reads a missing object')\nstack traceback:"));
}
