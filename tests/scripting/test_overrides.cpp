// --set overrides: by param(name, default) while the file runs, else by dotted path into the
// returned table; and the seeding of math.random around them.
#include <algorithm>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "graspsim/scripting/lua_sandbox.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "scenario_files.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;
using graspsim::Vec3;
using graspsim::scripting::LoadOptions;
using graspsim::scripting::Scenario;
using scripting_test::data_path;
using scripting_test::load_error;
using scripting_test::write_scenario;

namespace {

Scenario load_with(const std::string& file, std::vector<std::string> sets) {
  LoadOptions options;
  options.sets = std::move(sets);
  return Scenario::load(data_path(file), options);
}

std::string error_with(const std::string& file, std::vector<std::string> sets) {
  LoadOptions options;
  options.sets = std::move(sets);
  return load_error(data_path(file), options);
}

bool has_line(const Scenario& s, const std::string& line) {
  return std::find(s.parameters().begin(), s.parameters().end(), line) != s.parameters().end();
}

}  // namespace

TEST_CASE("a --set changes values by dotted path, naming objects, fingers and expectations",
          "[scenario][set]") {
  const Scenario s = load_with("valid.lua", {
      "duration=3",
      "rates.physics=50",
      "floor.material.mu=0.25",
      "objects.box.mass=0.5",
      "objects.box.position=0,0,0.1",
      "objects.lid.velocity.1=-1",   // one element of an array
      "fingers.thumb.stiffness=600",
      "fingers.index.trajectory.2.t=1.5",
      "expect.box lifted.at=2.75",
      "objects.lid.material.mu=0.3",   // absent in the file, but a field of the format
      "name=renamed",
  });
  CHECK(s.duration() == 3.0);
  CHECK(s.model().rates.physics == 50);
  CHECK(s.model().floor.material.mu == 0.25);
  CHECK(s.model().bodies[0].mass == 0.5);
  CHECK(s.model().bodies[0].position == Vec3(0, 0, 0.1));
  CHECK(s.model().bodies[1].velocity == Vec3(-1, 0, 0));
  CHECK(s.model().fingers[0].stiffness == 600);
  CHECK(s.expectations()[0].at == 2.75);
  CHECK(s.model().bodies[1].material.mu == 0.3);
  CHECK(s.name() == "renamed");
  // ... and parameters() shows the values the run used, still sorted.
  CHECK(std::is_sorted(s.parameters().begin(), s.parameters().end()));
  CHECK(has_line(s, "duration = 3"));
  CHECK(has_line(s, "objects.box.position = 0,0,0.10000000000000001"));
  CHECK(has_line(s, "fingers.index.trajectory.2.t = 1.5"));
  CHECK(has_line(s, "objects.lid.material.mu = 0.29999999999999999"));
  CHECK(has_line(s, "name = renamed"));
  CHECK_FALSE(has_line(s, "duration = 2.5"));
}

TEST_CASE("a --set path=nil removes a field, so an object can switch from density to mass",
          "[scenario][set]") {
  const Scenario s = load_with("valid.lua", {"objects.lid.density=nil", "objects.lid.mass=0.1"});
  CHECK(s.model().bodies[1].mass == 0.1);
  CHECK_FALSE(has_line(s, "objects.lid.density = 780"));
}

TEST_CASE("param(name, default) returns the --set value, typed like its default, takes the set, "
          "and is listed in parameters()",
          "[scenario][set]") {
  const Scenario plain = load_with("params.lua", {});
  CHECK(plain.description() == "plain");
  CHECK(plain.model().floor.enabled);
  const Scenario s = load_with("params.lua", {"lift=0.1", "label=42", "use_floor=false", "start=0,0.5,1"});
  CHECK(s.description() == "42");   // a string default takes the text as it is
  CHECK_FALSE(s.model().floor.enabled);
  auto thumb = s.make_trajectory(0);
  CHECK(thumb->position(0.0) == Vec3(0, 0.5, 1));
  CHECK(thumb->position(5.0) == Vec3(0, 0.5, 1.1));   // held after the last waypoint
  CHECK(has_line(s, "description = 42"));
  // Every param() value is a parameter of the run, set or not, under the name --set takes.
  CHECK(has_line(plain, "lift = 0.050000000000000003"));
  CHECK(has_line(plain, "start = -0.10000000000000001,0,0.040000000000000001"));
  CHECK(has_line(s, "lift = 0.10000000000000001"));
  CHECK(has_line(s, "label = 42"));
  CHECK(has_line(s, "use_floor = false"));
  CHECK(has_line(s, "start = 0,0.5,1"));
}

TEST_CASE("param() rejects a --set of another type than its default, naming the --set, and a "
          "misspelt param is an error suggesting the params",
          "[scenario][set]") {
  const std::string path = data_path("params.lua");
  const int line = scripting_test::line_of(path, "param(\"lift\"");
  CHECK_THAT(error_with("params.lua", {"lift=high"}),
             StartsWith(path + ":" + std::to_string(line) +
                        ": --set lift=high: param 'lift' expects a number, like its default"));
  CHECK_THAT(error_with("params.lua", {"use_floor=1"}),
             Contains("--set use_floor=1: param 'use_floor' expects a boolean"));
  // A misspelt param is not taken by param(), so it is an unknown path, with the params suggested.
  CHECK(error_with("params.lua", {"lfit=0.1"}) ==
        path + ": --set lfit=0.1: unknown field or param 'lfit' (did you mean 'lift'?)");
  CHECK(error_with("params.lua", {"zzz=0.1"}) ==
        path + ": --set zzz=0.1: unknown field or param 'zzz' (known fields: name, description, "
               "duration, seed, rates, gravity, integrator, implicit_order, local_model, stability, gyroscopic, grasp, floor, sleep, objects, "
               "fingers, expect; params: label, lift, start, use_floor)");
}

TEST_CASE("a --set path that is not in the table nor in the format is an error with a suggestion",
          "[scenario][set]") {
  const std::string path = data_path("valid.lua");
  CHECK(error_with("valid.lua", {"objects.box.mas=1"}) ==
        path + ": --set objects.box.mas=1: unknown field 'mas' (did you mean 'mass'?)");
  CHECK(error_with("valid.lua", {"objects.bx.mass=1"}) ==
        path + ": --set objects.bx.mass=1: no object named 'bx' (objects: box, lid)");
  CHECK(error_with("valid.lua", {"fingers.pinky.stiffness=1"}) ==
        path + ": --set fingers.pinky.stiffness=1: no finger named 'pinky' (fingers: thumb, index)");
  CHECK(error_with("valid.lua", {"lift=0.1"}) ==   // not a param of this file, not a field
        path + ": --set lift=0.1: unknown field 'lift' (known fields: name, description, duration, "
               "seed, rates, gravity, integrator, implicit_order, local_model, stability, gyroscopic, grasp, floor, sleep, objects, fingers, expect)");
  CHECK(error_with("valid.lua", {"duration.x=1"}) ==
        path + ": --set duration.x=1: 'duration' is a number, not a table");
  CHECK(error_with("valid.lua", {"fingers.index.trajectory.9.t=1"}) ==
        path + ": --set fingers.index.trajectory.9.t=1: '9' is not an element of "
               "fingers.index.trajectory (1..3)");
  CHECK(error_with("valid.lua", {"duration"}) ==
        path + ": --set duration: expected name=value (like objects.box.mass=0.5)");
  // A set value of the wrong type is caught like a wrong value in the file.
  CHECK(error_with("valid.lua", {"fingers.index.stiffness=stiff"}) ==
        path + ": fingers[2] 'index': stiffness: expected a number, got string");
}

// Lua 5.4 seeds math.random from the clock; graspsim seeds it with --set seed (else 0) before
// the file runs, and with the scenario's final seed before any trajectory or check runs.
TEST_CASE("math.random is seeded from --set seed while loading and from the scenario's seed after",
          "[scenario][set]") {
  const std::string path = write_scenario("random_description.lua", R"(
    return {
      description = tostring(math.random(1, 1000000000)),
      duration = 1,
      seed = 3,
      fingers = { { name = "thumb", trajectory = function(t) return math.random(), 0, 0 end } },
    })");
  const auto load = [&](std::vector<std::string> sets) {
    LoadOptions options;
    options.sets = std::move(sets);
    return Scenario::load(path, options);
  };
  CHECK(load({}).description() == load({"seed=0"}).description());
  CHECK(load({"seed=5"}).description() == load({"seed=5"}).description());
  CHECK(load({"seed=5"}).description() != load({"seed=6"}).description());

  graspsim::scripting::LuaSandbox reference;
  reference.seed_random(3);
  const double first = std::stod(reference.run("return math.random()", "reference.lua")[0]);
  const Scenario s = load({});
  CHECK(s.seed() == 3);
  CHECK(s.make_trajectory(0)->position(0.0).x() == first);
  CHECK(load({"seed=9"}).make_trajectory(0)->position(0.0).x() != first);
  CHECK_THAT(load_error(path, LoadOptions{{"seed=-1"}, {}, {}, {}}),
             Contains("--set seed=-1: seed must be an integer >= 0"));
}
