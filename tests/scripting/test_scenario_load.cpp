// Loading valid scenarios: every field of the format reaches the Model, the finger set-ups, the
// trajectories and the expectations with exactly the value the file gives, or the default.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "graspsim/scripting/scenario.hpp"
#include "scenario_files.hpp"

using graspsim::box_inertia;
using graspsim::kInfinity;
using graspsim::Material;
using graspsim::Quat;
using graspsim::Vec3;
using graspsim::scripting::Scenario;
using scripting_test::data_path;
using scripting_test::read_text;

// Values written in the file are parsed by Lua into the same doubles as C++ literals, and the
// loader only halves sizes (exact) and multiplies density by volume in the order x y z, so
// every comparison below is exact except the normalised quaternion.
TEST_CASE("a valid scenario converts to the exact Model values", "[scenario][load]") {
  const Scenario s = Scenario::load(data_path("valid.lua"));
  CHECK(s.path() == data_path("valid.lua"));
  CHECK(s.source() == read_text(data_path("valid.lua")));
  CHECK(s.name() == "two_box_grasp");
  CHECK(s.description() == "two fingers squeeze a box off the floor");
  CHECK(s.duration() == 2.5);
  CHECK(s.seed() == 7);

  const graspsim::Model& m = s.model();
  CHECK(m.rates.servo == 3000);
  CHECK(m.rates.haptic == 1000);
  CHECK(m.rates.physics == 100);
  CHECK(m.gravity == Vec3(0, 0, -9.81));
  CHECK(m.floor.enabled);
  CHECK(m.floor.height == -0.01);
  CHECK(m.floor.material.mu == 0.9);
  CHECK(m.floor.material.stiffness == 2000);
  CHECK(m.floor.material.damping == 12);

  REQUIRE(m.bodies.size() == 2);
  const graspsim::BodyParams& box = m.bodies[0];
  CHECK(box.name == "box");
  CHECK(box.shape.kind == graspsim::ShapeKind::kBox);
  CHECK(box.shape.half_extents == Vec3(0.04, 0.03, 0.02));
  CHECK(box.mass == 0.4);
  CHECK(box.inertia == box_inertia(0.4, Vec3(0.04, 0.03, 0.02)));   // the default inertia
  CHECK(box.position == Vec3(0, 0, 0.02));
  CHECK(box.orientation.coeffs() == Quat::Identity().coeffs());
  CHECK(box.velocity == Vec3::Zero());
  CHECK(box.angular_velocity == Vec3::Zero());
  CHECK(box.material.mu == 0.8);
  CHECK(box.material.stiffness == 250);
  CHECK(box.material.damping == 5);

  const graspsim::BodyParams& lid = m.bodies[1];
  CHECK(lid.name == "lid");
  CHECK(lid.mass == 780 * 0.1 * 0.1 * 0.01);   // density times volume
  CHECK(lid.inertia == Vec3(1e-4, 2e-4, 2.5e-4));
  CHECK(lid.position == Vec3(0, 0, 0.1));
  // {2^-0.5, 0, 0, 2^-0.5} is unit to round-off; it is normalised, so it may move by an ulp.
  CHECK(lid.orientation.w() == Approx(std::sqrt(0.5)).epsilon(1e-15));
  CHECK(lid.orientation.z() == Approx(std::sqrt(0.5)).epsilon(1e-15));
  CHECK(lid.orientation.x() == 0.0);
  CHECK(lid.orientation.norm() == Approx(1.0).epsilon(1e-15));
  CHECK(lid.velocity == Vec3(0.1, 0, 0));
  CHECK(lid.angular_velocity == Vec3(0, 0, 1));
  const Material defaults;
  CHECK(lid.material.mu == defaults.mu);
  CHECK(lid.material.stiffness == defaults.stiffness);
  CHECK(lid.material.damping == defaults.damping);

  REQUIRE(m.fingers.size() == 2);
  CHECK(m.fingers[0].name == "thumb");
  CHECK(m.fingers[0].stiffness == 400);
  CHECK(m.fingers[0].damping == 3.5);
  CHECK(m.fingers[1].name == "index");
  CHECK(m.fingers[1].stiffness == graspsim::FingerParams{}.stiffness);
  CHECK(m.fingers[1].damping == graspsim::FingerParams{}.damping);
  REQUIRE(s.fingers().size() == 2);
  CHECK(s.fingers()[0].limits.max_force == 8);
  CHECK(s.fingers()[1].limits.max_force == 10);

  REQUIRE(s.expectations().size() == 1);
  CHECK(s.expectations()[0].what == "box lifted");
  CHECK(s.expectations()[0].at == 2.0);
  CHECK(s.expectations()[0].function_ref != 0);
}

TEST_CASE("fields left out take the documented defaults", "[scenario][load]") {
  const Scenario s = Scenario::load(data_path("minimal.lua"));
  CHECK(s.name() == "minimal");   // the file name without .lua
  CHECK(s.description().empty());
  CHECK(s.seed() == 0);
  const graspsim::Model& m = s.model();
  const graspsim::Rates rates;
  CHECK(m.rates.servo == rates.servo);
  CHECK(m.rates.haptic == rates.haptic);
  CHECK(m.rates.physics == rates.physics);
  CHECK(m.gravity == Vec3(0, 0, -9.81));
  CHECK_FALSE(m.floor.enabled);
  REQUIRE(m.bodies.size() == 1);
  CHECK(m.bodies[0].shape.half_extents == Vec3(0.05, 0.05, 0.05));
  CHECK(m.bodies[0].inertia == box_inertia(1.0, Vec3(0.05, 0.05, 0.05)));
  CHECK(m.bodies[0].position == Vec3::Zero());
  REQUIRE(m.fingers.size() == 1);
  CHECK(m.fingers[0].stiffness == graspsim::FingerParams{}.stiffness);
  CHECK(s.fingers()[0].limits.max_force == graspsim::hw::DeviceLimits{}.max_force);
  CHECK(s.expectations().empty());
}

// The trace records parameters() so a run explains itself; the paths are the ones --set takes.
TEST_CASE("parameters() lists every non-function value as sorted 'path = value' lines",
          "[scenario][load]") {
  const Scenario s = Scenario::load(data_path("valid.lua"));
  const std::vector<std::string>& p = s.parameters();
  CHECK(std::is_sorted(p.begin(), p.end()));
  const auto has = [&](const std::string& line) {
    return std::find(p.begin(), p.end(), line) != p.end();
  };
  CHECK(has("duration = 2.5"));
  CHECK(has("seed = 7"));
  CHECK(has("rates.physics = 100"));
  CHECK(has("gravity = 0,0,-9.8100000000000005"));   // %.17g
  CHECK(has("floor.material.mu = 0.90000000000000002"));
  CHECK(has("objects.box.mass = 0.40000000000000002"));
  CHECK(has("objects.box.name = box"));
  CHECK(has("objects.lid.density = 780"));
  CHECK(has("fingers.index.interpolation = linear"));
  CHECK(has("fingers.index.trajectory.2.t = 1"));
  CHECK(has("fingers.thumb.trajectory.1.p = -0.10000000000000001,0,0.02"));
  CHECK(has("expect.box lifted.at = 2"));
  for (const std::string& line : p) CHECK(line.find("check") == std::string::npos);   // functions left out
}

// The gyroscopic option and the grasp rules (paper 3.1, 3.2, 5) convert to the Model's enums
// and values; a gimbal finger is named and resolved to its index.
TEST_CASE("gyroscopic, grasp and kinetic friction fields convert to the model", "[scenario][load]") {
  graspsim::scripting::LoadOptions options;
  options.sets = {"gyroscopic=implicit", "grasp.torsion=gimbal", "grasp.critical_area=2e-5",
                  "grasp.gimbal_finger=index", "grasp.dead_band=0.003",
                  "objects.box.material.mu_kinetic=0.3", "objects.box.material.viscous=7",
                  "fingers.thumb.radius=0.008"};
  const auto s = graspsim::scripting::Scenario::load(scripting_test::data_path("valid.lua"), options);
  const graspsim::Model& m = s.model();
  CHECK(m.gyroscopic == graspsim::Gyroscopic::kImplicit);
  CHECK(m.grasp.torsion == graspsim::Torsion::kGimbal);
  CHECK(m.grasp.critical_area == 2e-5);
  CHECK(m.grasp.gimbal_finger == 1);
  CHECK(m.grasp.dead_band == 0.003);
  CHECK(m.bodies[0].material.mu_kinetic == 0.3);
  CHECK(m.bodies[0].material.viscous == 7.0);
  CHECK(m.fingers[0].radius == 0.008);
  CHECK(m.fingers[1].radius == 0.0);
  CHECK(graspsim::kinetic_mu(m.bodies[1].material) == m.bodies[1].material.mu);   // unset: = mu
}

// stability: absent or "warn" only warns, "refuse" stops the run at an unstable mode; any other
// value is an error naming the field and the choices.
TEST_CASE("the stability field chooses between a warning and a refusal", "[scenario][load]") {
  const auto refuses = [](std::vector<std::string> sets) {
    graspsim::scripting::LoadOptions options;
    options.sets = std::move(sets);
    return graspsim::scripting::Scenario::load(scripting_test::data_path("valid.lua"), options).refuse_unstable();
  };
  CHECK_FALSE(refuses({}));
  CHECK_FALSE(refuses({"stability=warn"}));
  CHECK(refuses({"stability=refuse"}));
  graspsim::scripting::LoadOptions options;
  options.sets = {"stability=stop"};
  CHECK_THAT(scripting_test::load_error(scripting_test::data_path("valid.lua"), options),
             Catch::Contains("stability") && Catch::Contains("refuse"));
}

// sleep: absent is off; true takes the defaults; a table (here made by --set of its fields) turns
// it on with its fields.
TEST_CASE("the sleep field converts to the model", "[scenario][load]") {
  const auto load = [](std::vector<std::string> sets) {
    graspsim::scripting::LoadOptions options;
    options.sets = std::move(sets);
    return graspsim::scripting::Scenario::load(scripting_test::data_path("valid.lua"), options).model().sleep;
  };
  CHECK_FALSE(load({}).enabled);
  const graspsim::SleepParams on = load({"sleep=true"});
  CHECK(on.enabled);
  CHECK(on.time == graspsim::SleepParams{}.time);
  const graspsim::SleepParams set = load({"sleep.time=0.25", "sleep.linear_speed=0.002"});
  CHECK(set.enabled);
  CHECK(set.time == 0.25);
  CHECK(set.linear_speed == 0.002);
}
