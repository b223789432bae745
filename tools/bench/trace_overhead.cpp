// Logging overhead benchmark (issue 4, item 2): the two-finger lift run with the trace off, on,
// and on with --compress, interleaved, in one process. Prints the median wall time of each,
// the overhead of logging as a share of the run, and the trace size per simulated second.
// Not a test (tests never time things): run it by hand on an idle machine,
//   ./build/tools/bench_trace_overhead [REPEATS] [SCENARIO] [DURATION_S]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "app/run.hpp"
#include "graspsim/scripting/scenario.hpp"

using namespace graspsim;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 7;
  const std::string path = argc > 2 ? argv[2] : std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/two_finger_lift.lua";
  scripting::LoadOptions load;
  if (argc > 3) load.sets.push_back(std::string("duration=") + argv[3]);
  const auto scenario = scripting::Scenario::load(path, load);
  const std::string out = (std::filesystem::temp_directory_path() / "graspsim_bench_trace.h5").string();

  struct Variant {
    const char* name;
    bool trace;
    int compression;
    std::vector<double> wall;
    std::uintmax_t bytes = 0;
  };
  std::vector<Variant> variants = {{"off", false, 0, {}}, {"on", true, 0, {}}, {"on, --compress 4", true, 4, {}}};
  double simulated = 0.0;
  for (int r = 0; r < repeats + 1; ++r) {   // the first round warms caches and is dropped
    for (Variant& v : variants) {
      app::RunOptions options;
      options.out = out;
      options.write_trace = v.trace;
      options.compression = v.compression;
      const app::RunResult result = app::run_scenario(scenario, options);
      if (!result.error.empty()) {
        std::fprintf(stderr, "bench: %s\n", result.error.c_str());
        return 1;
      }
      simulated = result.simulated;
      if (r > 0) v.wall.push_back(result.wall);
      if (v.trace) v.bytes = std::filesystem::file_size(out);
    }
  }
  std::remove(out.c_str());
  const double off = median(variants[0].wall);
  std::printf("%s: %.1f s simulated, %d repeats (median wall time)\n", scenario.name().c_str(), simulated, repeats);
  for (const Variant& v : variants) {
    const double wall = median(v.wall);
    std::printf("  trace %-18s %8.4f s  (%5.1fx real time)  on/off %.3f, logging %+5.1f%% of the run", v.name,
                wall, simulated / wall, wall / off, 100.0 * (wall - off) / wall);
    if (v.trace) std::printf("  trace %.1f kB per simulated s", v.bytes / 1024.0 / simulated);
    std::printf("\n");
  }
  return 0;
}
