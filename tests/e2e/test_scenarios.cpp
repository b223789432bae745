// Every scenario of the library runs end to end at its own rates and meets its expectations.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "app/run.hpp"
#include "graspsim/scripting/scenario.hpp"

// A scenario states what it shows and checks it: a run that ends early or fails an expectation
// fails here, naming the scenario and the expectation. Files are taken in sorted order.
TEST_CASE("every scenario in scenarios/ meets its expectations", "[e2e][scenario]") {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(GRASPSIM_SOURCE_DIR) + "/scenarios")) {
    if (entry.path().extension() == ".lua") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  REQUIRE(files.size() >= 2);
  for (const std::string& file : files) {
    const auto scenario = graspsim::scripting::Scenario::load(file);
    graspsim::app::RunOptions options;
    options.out = std::string(GRASPSIM_TEST_TMP) + "/scenario_" + scenario.name() + ".h5";
    const graspsim::app::RunResult result = graspsim::app::run_scenario(scenario, options);
    INFO(file << ": " << result.error);
    CHECK(result.error.empty());
    CHECK(!result.expectations.empty());
    for (const auto& e : result.expectations) {
      INFO(e.what << ": " << e.detail);
      CHECK(e.passed);
    }
  }
}
