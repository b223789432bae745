// Every scenario of the library runs end to end at its own rates and meets its expectations.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "app/run.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "tests/support/library.hpp"

// A scenario states what it shows and checks it: a run that ends early or fails an expectation
// fails here, naming the scenario and the expectation. Files are taken in sorted order. Each
// runs at its own rates (the paper's 3000/500/50 Hz) and with every loop at 3000 Hz: the
// physics must not depend on the paper's slow physics loop to work.
TEST_CASE("every scenario in scenarios/ meets its expectations at two sets of rates", "[e2e][scenario]") {
  const std::vector<std::string> files = graspsim::test::library_scenarios();
  REQUIRE(files.size() >= 2);
  const std::vector<std::vector<std::string>> rate_sets = {
      {}, {"rates.servo=3000", "rates.haptic=3000", "rates.physics=3000"}};
  for (const std::string& file : files) {
    for (const auto& rates : rate_sets) {
      graspsim::scripting::LoadOptions load;
      load.sets = rates;
      const auto scenario = graspsim::scripting::Scenario::load(file, load);
      graspsim::app::RunOptions options;
      options.out = std::string(GRASPSIM_TEST_TMP) + "/scenario_" + scenario.name() + ".h5";
      const graspsim::app::RunResult result = graspsim::app::run_scenario(scenario, options);
      INFO(file << (rates.empty() ? " at its own rates" : " with every loop at 3000 Hz") << ": "
                << result.error);
      CHECK(result.error.empty());
      CHECK(!result.expectations.empty());
      for (const auto& e : result.expectations) {
        INFO(e.what << ": " << e.detail);
        CHECK(e.passed);
      }
    }
  }
}

// Rotation end to end (paper 3.1 residual torque, 3.3 pushing): the same push 3 cm off-centre
// turns the box away from the finger (the scenario checks the sign: a push in +x at +y gives
// T_z = -y F < 0) while it still slides and stays on its base.
TEST_CASE("an off-centre push turns the box end to end", "[e2e][scenario]") {
  graspsim::scripting::LoadOptions load;
  load.sets = {"offset=0.03"};
  const auto scenario = graspsim::scripting::Scenario::load(
      std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/push_along_floor.lua", load);
  graspsim::app::RunOptions options;
  options.out = std::string(GRASPSIM_TEST_TMP) + "/scenario_push_off_centre.h5";
  const graspsim::app::RunResult result = graspsim::app::run_scenario(scenario, options);
  REQUIRE(result.error.empty());
  for (const auto& e : result.expectations) {
    INFO(e.what << ": " << e.detail);
    CHECK(e.passed);
  }
}
