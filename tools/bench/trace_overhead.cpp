// Logging overhead benchmark (recordings/README.md, "Cost"): the two-finger lift run with the trace
// off, on (HDF5 writing on the writer thread, as `graspsim run` does), on with the writing on the
// run loop's own thread, and on with --compress, interleaved, in one process. Prints, for each, the
// median over the repeats of: the whole run_scenario call's wall time (creating the file, writing
// its attributes, running, closing it); the run loop thread's CPU time over the whole call (what
// logging costs the thread that steps the simulation and would serve the devices; least sensitive
// to other processes on a shared machine); the process's CPU time (all threads: the cost on one
// core); the overhead of logging as a share of each (1 - off/on); and the trace size per simulated
// second.
// Not a test (tests never time things): run it by hand on an idle machine,
//   ./build/tools/bench_trace_overhead [REPEATS] [SCENARIO] [DURATION_S] [NAME=VALUE...]
// (the NAME=VALUE arguments are --set overrides, e.g. rates.physics=3000 rates.haptic=3000)
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
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

double cpu_seconds(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
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
  for (int i = 4; i < argc; ++i) load.sets.push_back(argv[i]);
  std::optional<scripting::Scenario> loaded;
  try {
    loaded.emplace(scripting::Scenario::load(path, load));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench: %s\n", e.what());
    return 2;
  }
  const scripting::Scenario& scenario = *loaded;
  const std::string out = (std::filesystem::temp_directory_path() / "graspsim_bench_trace.h5").string();

  struct Variant {
    const char* name;
    bool trace;
    bool background;
    int compression;
    std::vector<double> whole = {};    // s, wall time of the whole run_scenario call
    std::vector<double> thread = {};   // s, CPU time of this (the run loop's) thread
    std::vector<double> cpu = {};      // s, process CPU time of the whole call
    std::uintmax_t bytes = 0;
  };
  std::vector<Variant> variants = {{"off", false, true, 0},
                                   {"on", true, true, 0},
                                   {"on, one thread", true, false, 0},
                                   {"on, --compress 4", true, true, 4}};
  double simulated = 0.0;
  for (int r = 0; r < repeats + 1; ++r) {   // the first round warms caches and is dropped
    for (Variant& v : variants) {
      app::RunOptions options;
      options.out = out;
      std::remove(out.c_str());   // see below: a truncated file costs ext4 a flush on close
      options.trace.write = v.trace;
      options.trace.compression = v.compression;
      options.trace.background_writer = v.background;
      const double wall0 = wall_seconds();
      const double thread0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
      const double cpu0 = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID);
      const app::RunResult result = app::run_scenario(scenario, options);
      const double cpu1 = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID);
      const double thread1 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
      const double wall1 = wall_seconds();
      if (!result.error.empty()) {
        std::fprintf(stderr, "bench: %s\n", result.error.c_str());
        return 1;
      }
      simulated = result.simulated;
      if (r > 0) {
        v.whole.push_back(wall1 - wall0);
        v.thread.push_back(thread1 - thread0);
        v.cpu.push_back(cpu1 - cpu0);
      }
      if (v.trace) v.bytes = std::filesystem::file_size(out);
    }
  }
  std::remove(out.c_str());
  std::printf("%s: %.1f s simulated, %d repeats (medians; logging = 1 - off/on, its share of the run)\n",
              scenario.name().c_str(), simulated, repeats);
  std::printf("  %-18s %22s %22s %22s %10s\n", "trace", "whole run wall", "run loop thread CPU",
              "process CPU", "kB per s");
  const double off_whole = median(variants[0].whole);
  const double off_thread = median(variants[0].thread);
  const double off_cpu = median(variants[0].cpu);
  for (const Variant& v : variants) {
    const double whole = median(v.whole), thread = median(v.thread), cpu = median(v.cpu);
    std::printf("  %-18s %8.2f ms (%5.1f%%) %8.2f ms (%5.1f%%) %8.2f ms (%5.1f%%)", v.name, 1e3 * whole,
                100.0 * (1.0 - off_whole / whole), 1e3 * thread, 100.0 * (1.0 - off_thread / thread),
                1e3 * cpu, 100.0 * (1.0 - off_cpu / cpu));
    if (v.trace) std::printf(" %10.1f", v.bytes / 1024.0 / simulated);
    std::printf("\n");
  }
  std::printf("  (whole run: %.0fx real time with the trace off, %.0fx on)\n", simulated / off_whole,
              simulated / median(variants[1].whole));
  return 0;
}
