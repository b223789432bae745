// Real-time factor benchmark (README.md, "Speed targets"): a scenario run through the whole run
// loop (app::run_scenario: Lua trajectories, devices, engine, expectations), with the trace off and
// on, at the scenario's rates and with every loop at 3000 Hz. Prints the median wall time of the
// run loop (RunResult::wall) over the repeats and the real-time factor, simulated s / wall s.
// Not a test (tests never time things): run it by hand, on a quiet machine,
//   ./build/tools/graspsim_realtime_factor [REPEATS] [SCENARIO]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "app/run.hpp"
#include "graspsim/scripting/scenario.hpp"

using namespace graspsim;

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  const std::string path = argc > 2 ? argv[2] : std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/two_finger_lift.lua";
  const std::string out = (std::filesystem::temp_directory_path() / "graspsim_bench_rtf.h5").string();
  struct Case {
    const char* name;
    std::vector<std::string> sets;
    bool trace;
    std::vector<double> wall;
    double simulated = 0.0;
  };
  std::vector<Case> cases = {
      {"scenario rates, trace on", {}, true, {}},
      {"scenario rates, trace off", {}, false, {}},
      {"all loops 3000 Hz, trace off", {"rates.physics=3000", "rates.haptic=3000"}, false, {}},
  };
  for (int r = 0; r <= repeats; ++r) {   // run 0 warms up and is dropped
    for (Case& c : cases) {
      scripting::LoadOptions load;
      load.sets = c.sets;
      const auto scenario = scripting::Scenario::load(path, load);
      app::RunOptions options;
      options.out = out;
      options.trace.write = c.trace;
      const app::RunResult result = app::run_scenario(scenario, options);
      if (!result.error.empty()) {
        std::fprintf(stderr, "bench: %s\n", result.error.c_str());
        return 1;
      }
      c.simulated = result.simulated;
      if (r > 0) c.wall.push_back(result.wall);
    }
  }
  std::remove(out.c_str());
  std::printf("graspsim_realtime_factor: %s, %d repeats (median run-loop wall time)\n", path.c_str(), repeats);
  for (Case& c : cases) {
    std::sort(c.wall.begin(), c.wall.end());
    const double wall = c.wall[c.wall.size() / 2];
    std::printf("  %-30s %8.1f ms for %.1f s simulated: %6.0fx real time\n", c.name, 1e3 * wall, c.simulated,
                c.simulated / wall);
  }
  return 0;
}
