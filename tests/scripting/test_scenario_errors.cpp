// Bad scenario input: every mistake is a ScenarioError whose message starts with the scenario's
// path and names the problem (the line for Lua errors, the field for bad values).
#include <string>

#include <catch2/catch.hpp>

#include "graspsim/scripting/scenario.hpp"
#include "scenario_files.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::EndsWith;
using Catch::Matchers::StartsWith;
using graspsim::scripting::LoadOptions;
using graspsim::scripting::Scenario;
using scripting_test::data_path;
using scripting_test::line_of;
using scripting_test::load_error;
using scripting_test::variant;

namespace {

// The message for valid.lua with `from` replaced by `to`, and the path of that variant.
struct Broken {
  std::string path;
  std::string message;
};
Broken broken(const std::string& name, const std::string& from, const std::string& to) {
  const std::string path = variant("valid.lua", name + ".lua", from, to);
  return Broken{path, load_error(path)};
}

// The error loading valid.lua with these --set overrides ("no error" if it loads).
std::string message(std::vector<std::string> sets) {
  graspsim::scripting::LoadOptions options;
  options.sets = std::move(sets);
  try {
    graspsim::scripting::Scenario::load(scripting_test::data_path("valid.lua"), options);
  } catch (const graspsim::scripting::ScenarioError& e) {
    return std::string(e.what());
  }
  return std::string("no error");
}

}  // namespace

TEST_CASE("a missing file is reported with the OS reason", "[scenario][errors]") {
  const std::string path = data_path("no_such_scenario.lua");
  CHECK(load_error(path) == "cannot open scenario '" + path + "': No such file or directory");
}

TEST_CASE("a syntax error gives Lua's message with the file and line", "[scenario][errors]") {
  const std::string path = data_path("syntax_error.lua");
  const int line = line_of(path, "SYNTAX ERROR HERE");
  CHECK_THAT(load_error(path), StartsWith(path + ":" + std::to_string(line) + ": '}' expected"));
}

TEST_CASE("a runtime error while loading gives file:line and a traceback", "[scenario][errors]") {
  const std::string path = data_path("runtime_error.lua");
  const int line = line_of(path, "RUNTIME ERROR HERE");
  const std::string message = load_error(path);
  CHECK_THAT(message, StartsWith(path + ":" + std::to_string(line) + ": attempt to index a nil value"));
  CHECK_THAT(message, Contains("stack traceback:"));
  CHECK_THAT(message, Contains(path + ":" + std::to_string(line) + ": in "));
}

TEST_CASE("a file that does not return a table is an error saying so", "[scenario][errors]") {
  const std::string path = data_path("not_a_table.lua");
  CHECK(load_error(path) ==
        path + ": the scenario must return a table (return { duration = ..., objects = ..., "
               "fingers = ... }), but it returned nil");
}

// Lua keeps only the first of several values where one is asked for; a scenario file's second
// table (a scenario meant to run, or a stray value) is refused, naming the file, not dropped.
TEST_CASE("a file that returns two tables is refused, naming the file", "[scenario][errors]") {
  const std::string path = data_path("two_tables.lua");
  CHECK(load_error(path) ==
        path + ": the scenario must return one table (return { duration = ..., objects = ..., fingers = ... }), but "
               "it returned 2 values (table, table): only one can be the scenario");
}

TEST_CASE("an endless loop while loading stops with the budget message", "[scenario][errors]") {
  LoadOptions options;
  options.limits.load_instructions = 2'000'000;   // the default 2e8 takes about a second
  const std::string path = data_path("endless_loop.lua");
  CHECK_THAT(load_error(path, options),
             StartsWith(path + ":3: instruction budget of 2000000 instructions exceeded (an endless loop?)"));
}

TEST_CASE("a memory bomb while loading stops with the memory-limit message", "[scenario][errors]") {
  LoadOptions options;
  options.limits.memory_mib = 64;
  const std::string path = data_path("memory_bomb.lua");
  CHECK(load_error(path, options) == path + ": memory limit of 64 MiB exceeded");
}

// Lua 5.4 randomises pairs() order per process, so unknown keys are reported sorted.
TEST_CASE("an unknown field is named with its place and the closest known name",
          "[scenario][errors]") {
  const Broken object = broken("unknown_object_field", "mass = 0.4", "mas = 0.4");
  CHECK(object.message == object.path + ": objects[1] 'box': unknown field 'mas' (did you mean 'mass'?)");
  const Broken top = broken("unknown_top_field", "duration = 2.5", "duraton = 2.5");
  CHECK(top.message == top.path + ": unknown field 'duraton' (did you mean 'duration'?)");
  const Broken rates = broken("unknown_rate", "physics = 100", "physic = 100");
  CHECK(rates.message == rates.path + ": rates: unknown field 'physic' (did you mean 'physics'?)");
  const Broken material = broken("unknown_material_field", "mu = 0.8, stiffness = 250",
                                 "mu = 0.8, stifness = 250");
  CHECK(material.message == material.path +
        ": objects[1] 'box': material: unknown field 'stifness' (did you mean 'stiffness'?)");
  const Broken waypoint = broken("unknown_waypoint_field", "{t = 1, p = {-0.03, 0, 0.02}}",
                                 "{t = 1, pos = {-0.03, 0, 0.02}}");
  CHECK(waypoint.message == waypoint.path +
        ": fingers[1] 'thumb': trajectory[2]: unknown field 'pos' (known fields: t, p, pitch)");
  const Broken two = broken("two_unknown_fields", "max_force = 8", "zeta = 1, alpha = 2");
  CHECK(two.message == two.path + ": fingers[1] 'thumb': unknown field 'alpha' (known fields: "
        "name, stiffness, damping, radius, max_force, trajectory, interpolation, device); unknown field 'zeta' (known "
        "fields: name, stiffness, damping, radius, max_force, trajectory, interpolation, device)");
  const Broken expectation = broken("unknown_expect_field", "at = 2,", "when = 2,");
  CHECK_THAT(expectation.message, StartsWith(expectation.path + ": expect[1] 'box lifted': unknown field 'when'"));
}

TEST_CASE("a value of the wrong type is named with its place and both types", "[scenario][errors]") {
  const Broken stiffness = broken("wrong_type", "{ name = \"index\", interpolation",
                                  "{ name = \"index\", stiffness = \"stiff\", interpolation");
  CHECK(stiffness.message == stiffness.path + ": fingers[2] 'index': stiffness: expected a number, got string");
  const Broken size = broken("wrong_size", "size = {0.08, 0.06, 0.04}", "size = {0.08, 0.06}");
  CHECK(size.message == size.path + ": objects[1] 'box': size: expected {x, y, z} (3 numbers), got 2 elements");
  const Broken element = broken("wrong_element", "position = {0, 0, 0.02}", "position = {0, '0', 0.02}");
  CHECK(element.message == element.path + ": objects[1] 'box': position[2]: expected a number, got string");
  const Broken rate = broken("fractional_rate", "servo = 3000", "servo = 2999.5");
  CHECK(rate.message == rate.path + ": rates.servo: expected an integer, got 2999.5");
  const Broken objects = broken("objects_by_name", "objects = {", "objects = { extra = 1,");
  CHECK_THAT(objects.message, StartsWith(objects.path + ": objects: expected an array of objects"));
}

TEST_CASE("bad values are named with their field (the engine's validate() and the loader's own "
          "checks)", "[scenario][errors]") {
  const Broken mass = broken("negative_mass", "mass = 0.4", "mass = -0.4");
  CHECK_THAT(mass.message, StartsWith(mass.path + ": objects[1] 'box': mass: must be > 0 kg"));
  const Broken mu = broken("negative_mu", "mu = 0.8", "mu = -0.1");
  CHECK_THAT(mu.message, StartsWith(mu.path + ": objects[1] 'box': material.mu: must be >= 0"));
  const Broken rate = broken("rate_not_dividing", "physics = 100", "physics = 70");
  CHECK(rate.message == rate.path + ": rates.physics: 70 Hz does not divide rates.servo = 3000 Hz");
  const Broken duration = broken("duration_not_whole", "duration = 2.5,", "duration = 2.5001,");
  CHECK_THAT(duration.message, StartsWith(duration.path + ": duration: 2.5001 s is not a whole "
                                          "number of servo periods at rates.servo = 3000 Hz"));
  const Broken both = broken("mass_and_density", "mass = 0.4", "mass = 0.4, density = 500");
  CHECK(both.message == both.path + ": objects[1] 'box': give either mass or density, not both");
  const Broken neither = broken("no_mass", "mass = 0.4,", "");
  CHECK(neither.message == neither.path + ": objects[1] 'box': give its mass (kg) or its density (kg/m^3)");
  const Broken density = broken("negative_density", "density = 780", "density = -780");
  CHECK_THAT(density.message, StartsWith(density.path + ": objects[2] 'lid': density: must be > 0 kg/m^3"));
  const Broken quaternion = broken("not_unit", "orientation = {2^-0.5, 0, 0, 2^-0.5}",
                                   "orientation = {1, 0, 0, 1}");
  CHECK_THAT(quaternion.message, StartsWith(quaternion.path + ": objects[2] 'lid': orientation: must be a unit quaternion"));
  const Broken times = broken("waypoints_out_of_order", "{t = 2, p = {0.03, 0, 0.1}}", "{t = 1, p = {0.03, 0, 0.1}}");
  CHECK_THAT(times.message, StartsWith(times.path + ": fingers[2] 'index': trajectory[3].t: 1 s does not come after"));
  const Broken shape = broken("unknown_shape", "shape = \"box\"", "shape = \"sphre\"");
  CHECK(shape.message == shape.path + ": objects[1] 'box': shape: unknown shape 'sphre' (did you mean 'sphere'?)");
  const Broken interpolation = broken("unknown_interpolation", "\"linear\"", "\"lnear\"");
  CHECK(interpolation.message == interpolation.path +
        ": fingers[2] 'index': interpolation: unknown interpolation 'lnear' (did you mean 'linear'?)");
  const Broken seed = broken("negative_seed", "seed = 7", "seed = -7");
  CHECK(seed.message == seed.path + ": seed: must be an integer >= 0 (got -7)");
  const Broken at = broken("late_check", "at = 2,", "at = 3,");
  CHECK(at.message == at.path + ": expect[1] 'box lifted': at: must be a time in [0, duration = 2.5] s (got 3)");
  const Broken name = broken("bad_name", "name = \"lid\"", "name = \"the lid\"");
  CHECK_THAT(name.message, StartsWith(name.path + ": objects[2] 'the lid': name: 'the lid' is not a valid name"));
  const Broken twice = broken("same_name", "name = \"lid\"", "name = \"box\"");
  CHECK_THAT(twice.message, StartsWith(twice.path + ": objects[2] 'box'") && Contains("used twice"));
  const Broken max_force = broken("zero_max_force", "max_force = 8", "max_force = 0");
  CHECK(max_force.message == max_force.path + ": fingers[1] 'thumb': max_force: must be > 0 N and finite (got 0)");
  const Broken check = broken("no_check", "check = function(sim)", "chek = function(sim)");
  CHECK_THAT(check.message, EndsWith("unknown field 'chek' (did you mean 'check'?)"));
  const Broken floor = broken("floor_number",
                              "floor = { height = -0.01, material = { mu = 0.9, stiffness = 2000, damping = 12 } },",
                              "floor = 1,");
  CHECK(floor.message == floor.path + ": floor: expected a table, true or false, got number");
}

// Bad grasp and gyroscopic values name their field.
TEST_CASE("bad gyroscopic, grasp and friction values are named with their field", "[scenario][errors]") {
  CHECK_THAT(message({"gyroscopic=sometimes"}), Catch::Contains("gyroscopic"));
  CHECK_THAT(message({"grasp.torsion=twist"}), Catch::Contains("torsion"));
  CHECK_THAT(message({"grasp.torsion=gravity_drop"}), Catch::Contains("grasp.critical_area"));
  CHECK_THAT(message({"grasp.torsion=gimbal", "grasp.critical_area=1e-5"}), Catch::Contains("grasp.gimbal_finger"));
  CHECK_THAT(message({"grasp.gimbal_finger=pinky"}), Catch::Contains("pinky"));
  CHECK_THAT(message({"grasp.dead_band=-1"}), Catch::Contains("grasp.dead_band"));
  CHECK_THAT(message({"objects.box.material.mu_kinetic=5"}), Catch::Contains("mu_kinetic") && Catch::Contains("<= mu"));
  CHECK_THAT(message({"objects.box.material.viscous=-1"}), Catch::Contains("viscous"));
  CHECK_THAT(message({"fingers.thumb.radius=-0.01"}), Catch::Contains("radius"));
}

// implicit_order is 1 or 2, and only with the implicit step (the paper's has one order).
TEST_CASE("a bad implicit_order names its field and the choices", "[scenario][errors]") {
  CHECK(message({"implicit_order=1"}) == "no error");
  CHECK(message({"implicit_order=2"}) == "no error");
  CHECK_THAT(message({"implicit_order=3"}), Catch::Contains("implicit_order") && Catch::Contains("must be 1 (backward Euler) or 2 (BDF2)"));
  CHECK_THAT(message({"implicit_order=1.5"}), Catch::Contains("implicit_order"));
  CHECK_THAT(message({"integrator=paper", "implicit_order=2"}), Catch::Contains("implicit_order") && Catch::Contains("needs integrator = \"implicit\""));
}

// Bad sleep values name their field.
TEST_CASE("bad sleep values are named with their field", "[scenario][errors]") {
  CHECK_THAT(message({"sleep.time=0"}), Catch::Contains("sleep.time") && Catch::Contains("> 0 s"));
  CHECK_THAT(message({"sleep.linear_speed=-1"}), Catch::Contains("sleep.linear_speed"));
  CHECK_THAT(message({"sleep=3"}), Catch::Contains("sleep") && Catch::Contains("expected a table, true or false"));
}

// The ceilings on a run's size (scenario.hpp, scripting/README.md "Ceilings"): rates.servo up to
// 100 kHz and duration up to 86,400 s load, one step over is refused naming the field and the
// ceiling (figures that would exhaust a machine: --duration 1e12, rates of 1e7 and 1e9 Hz). Loads
// only: nothing runs.
TEST_CASE("rates.servo and duration have ceilings: at the ceiling a scenario loads, one step over it is "
          "refused naming the figure", "[scenario][errors][ceiling]") {
  CHECK(message({"rates.servo=100000", "rates.haptic=100000", "rates.physics=100000"}) == "no error");
  CHECK_THAT(message({"rates.servo=100001", "rates.haptic=100001", "rates.physics=100001"}),
             Contains("rates.servo: 100001 Hz is over the ceiling of 100000 Hz"));
  for (const char* rate : {"10000000", "1000000000"}) {
    CHECK_THAT(message({std::string("rates.servo=") + rate}), Contains(std::string("rates.servo: ") + rate + " Hz is over the ceiling"));
  }
  CHECK(message({"duration=86400"}) == "no error");
  CHECK_THAT(message({"duration=86400.01"}), Contains("duration: 86400.01 s is over the ceiling of 86400 s"));
  CHECK_THAT(message({"duration=1e12"}), Contains("duration: 1e+12 s is over the ceiling of 86400 s (24 h of simulated time: 3e+15 servo ticks at 3000 Hz)"));
}
