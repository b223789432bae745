// Logging overhead benchmark (issue 4, item 2): the two-finger lift run with the trace off, on,
// and on with --compress, interleaved, in one process. Prints, for each, the median over the
// repeats of: the run loop's wall time (RunResult::wall: from the devices' start to the last
// tick, which includes declaring the trace's datasets and starting SWMR but not creating or
// closing the file), the whole run_scenario call's wall time (also creating the file, writing
// its attributes and closing it), and the whole call's CPU time (process CPU time: less
// sensitive than wall time to other processes on a shared machine); the overhead of logging as
// a share of each (1 - off/on); and the trace size per simulated second.
// Not a test (tests never time things): run it by hand on an idle machine,
//   ./build/tools/bench_trace_overhead [REPEATS] [SCENARIO] [DURATION_S]
#include <time.h>

#include <algorithm>
#include <chrono>
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

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
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
    std::vector<double> wall;    // s, run loop (RunResult::wall)
    std::vector<double> whole;   // s, wall time of the whole run_scenario call
    std::vector<double> cpu;     // s, process CPU time of the whole call
    std::uintmax_t bytes = 0;
  };
  std::vector<Variant> variants = {{"off", false, 0, {}, {}, {}}, {"on", true, 0, {}, {}, {}}, {"on, --compress 4", true, 4, {}, {}, {}}};
  double simulated = 0.0;
  for (int r = 0; r < repeats + 1; ++r) {   // the first round warms caches and is dropped
    for (Variant& v : variants) {
      app::RunOptions options;
      options.out = out;
      options.write_trace = v.trace;
      options.compression = v.compression;
      const double wall0 = wall_seconds();
      const double cpu0 = cpu_seconds();
      const app::RunResult result = app::run_scenario(scenario, options);
      const double cpu1 = cpu_seconds();
      const double wall1 = wall_seconds();
      if (!result.error.empty()) {
        std::fprintf(stderr, "bench: %s\n", result.error.c_str());
        return 1;
      }
      simulated = result.simulated;
      if (r > 0) {
        v.wall.push_back(result.wall);
        v.whole.push_back(wall1 - wall0);
        v.cpu.push_back(cpu1 - cpu0);
      }
      if (v.trace) v.bytes = std::filesystem::file_size(out);
    }
  }
  std::remove(out.c_str());
  std::printf("%s: %.1f s simulated, %d repeats (medians; logging = 1 - off/on, its share of the run)\n",
              scenario.name().c_str(), simulated, repeats);
  std::printf("  %-22s %22s %22s %22s %10s\n", "trace", "run loop wall", "whole run wall", "whole run CPU",
              "kB per s");
  const double off_wall = median(variants[0].wall);
  const double off_whole = median(variants[0].whole);
  const double off_cpu = median(variants[0].cpu);
  for (const Variant& v : variants) {
    const double wall = median(v.wall), whole = median(v.whole), cpu = median(v.cpu);
    std::printf("  %-22s %8.2f ms (%5.1f%%) %8.2f ms (%5.1f%%) %8.2f ms (%5.1f%%)", v.name, 1e3 * wall,
                100.0 * (1.0 - off_wall / wall), 1e3 * whole, 100.0 * (1.0 - off_whole / whole), 1e3 * cpu,
                100.0 * (1.0 - off_cpu / cpu));
    if (v.trace) std::printf(" %10.1f", v.bytes / 1024.0 / simulated);
    std::printf("\n");
  }
  std::printf("  (run loop: %.0fx real time with the trace off, %.0fx on)\n", simulated / off_wall,
              simulated / median(variants[1].wall));
  return 0;
}
