// What a loaded scenario does during a run: finger trajectories (waypoints or Lua functions of
// time) and expectations (Lua checks of a snapshot).
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
  CHECK_THAT(error_of([&] { stuck->position(0.0); }),
             Contains("instruction budget of 1000000 instructions exceeded (an endless loop?) "
                      "(fingers[6] 'stuck' trajectory at t = 0 s)"));
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

// Scripted gimbal pitch from a function: a fourth result (or a fourth element) is the pitch, 0
// when absent; anything but a finite number there is an error naming the finger and the time.
TEST_CASE("a trajectory function may return the gimbal pitch as a fourth value",
          "[scenario][trajectory][gimbal]") {
  const std::string path = scripting_test::write_scenario("pitch_function.lua", R"(return {
  duration = 1,
  fingers = {
    { name = "a", trajectory = function(t) return 0, 0, 0, 2 * t end },
    { name = "b", trajectory = function(t) return {1, 2, 3, -t} end },
    { name = "c", trajectory = function(t) return 1, 2, 3 end },
    { name = "d", trajectory = function(t) if t < 0.5 then return 0, 0, 0, "up" end return 0, 0, 0, 0 / 0 end },
  } })");
  const Scenario s = Scenario::load(path);
  CHECK(s.make_trajectory(0)->sample(0.25).gimbal == Vec3(0, 0.5, 0));
  const auto b = s.make_trajectory(1)->sample(0.5);
  CHECK(b.position == Vec3(1, 2, 3));
  CHECK(b.gimbal == Vec3(0, -0.5, 0));
  CHECK(s.make_trajectory(2)->sample(0.5).gimbal == Vec3::Zero());
  auto d = s.make_trajectory(3);
  CHECK(error_of([&] { d->sample(0.25); }) ==
        path + ": fingers[4] 'd' trajectory at t = 0.25 s: the function must return x, y, z (m) "
               "and optionally the gimbal pitch (rad), or {x, y, z[, pitch]}, but returned "
               "(number, number, number, string)");
  CHECK(error_of([&] { d->sample(0.75); }) ==
        path + ": fingers[4] 'd' trajectory at t = 0.75 s: the function returned a non-finite pitch (nan)");
  // None of these functions takes the view, so the runner need not keep it.
  CHECK_FALSE(s.uses_view());
}

// Waypoint pitch: on every waypoint or on none; a number.
TEST_CASE("waypoints carry a pitch on all or none of them", "[scenario][trajectory][gimbal]") {
  const auto scenario = [](const std::string& name, const std::string& waypoints) {
    return scripting_test::write_scenario(name, "return { duration = 1, fingers = { { name = 'thumb', trajectory = " +
                                                    waypoints + " } } }");
  };
  const std::string good = scenario("pitch_good.lua", "{ {t = 0, p = {0, 0, 0}, pitch = 0}, {t = 1, p = {0, 0, 0}, pitch = 1} }");
  const Scenario s = Scenario::load(good);
  CHECK(s.make_trajectory(0)->sample(0.5).gimbal.y() == Approx(0.5).margin(1e-15));   // s(1/2) = 1/2
  CHECK(s.make_trajectory(0)->sample(2.0).gimbal.y() == 1.0);

  const std::string missing = scenario("pitch_missing.lua", "{ {t = 0, p = {0, 0, 0}, pitch = 0}, {t = 1, p = {0, 0, 0}} }");
  CHECK(scripting_test::load_error(missing) ==
        missing + ": fingers[1] 'thumb': trajectory[2]: has no pitch but the first waypoint has one: "
                  "give pitch (rad) on every waypoint or on none");
  const std::string extra = scenario("pitch_extra.lua", "{ {t = 0, p = {0, 0, 0}}, {t = 1, p = {0, 0, 0}, pitch = 1} }");
  CHECK(scripting_test::load_error(extra) ==
        extra + ": fingers[1] 'thumb': trajectory[2].pitch: has a pitch but the first waypoint has none: "
                "give pitch (rad) on every waypoint or on none");
  const std::string text = scenario("pitch_text.lua", "{ {t = 0, p = {0, 0, 0}, pitch = 'up'} }");
  CHECK_THAT(scripting_test::load_error(text), StartsWith(text + ": fingers[1] 'thumb': trajectory[1].pitch: "));
}

// The view: a function with a second parameter (or ...) makes the scenario keep it; it is nil
// until the runner's first update_view, then the snapshot's values, read-only, the same shape as
// a check's `sim` (time, objects with position, orientation, rotation rows, velocity,
// angular_velocity, floor_contacts; fingers with hip, god_object, force, touching, phase, slip).
TEST_CASE("a trajectory function reads the view it is given", "[scenario][trajectory][feedback]") {
  const std::string path = scripting_test::write_scenario("view_read.lua", R"(return {
  duration = 1,
  objects = { { name = "box", size = {0.08, 0.08, 0.08}, mass = 0.4 } },
  fingers = {
    { name = "thumb", trajectory = function(t, sim)
        if sim == nil then return -1, -1, -1 end
        local b, f = sim.objects.box, sim.fingers.thumb
        local n = 0
        for _ in pairs(sim.objects) do n = n + 1 end
        return b.position[3] + sim.time, #b.rotation + b.rotation[3][3] + n,
               f.force[1] + (f.phase == "stick" and 100 or 0) + (f.touching == "box" and 1000 or 0)
      end },
  } })");
  const Scenario s = Scenario::load(path);
  CHECK(s.uses_view());
  auto thumb = s.make_trajectory(0);
  CHECK(thumb->position(0.0) == Vec3(-1, -1, -1));
  Snapshot now = snapshot(0.25, 0.5);
  now.fingers[0].phase = graspsim::ContactPhase::kStick;
  s.update_view(now);
  CHECK(thumb->position(0.3) == Vec3(0.75, 3 + 1 + 1, 2 + 100 + 1000));
  now.objects[0].position.z() = 0.125;   // updated in place: the same tables, new numbers
  now.time = 0.5;
  s.update_view(now);
  CHECK(thumb->position(0.6) == Vec3(0.625, 5, 1102));
}
