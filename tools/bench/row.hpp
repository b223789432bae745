// One row of the work-precision table (bench.csv) and how its cost is timed; shared by the
// cases' drivers in graspsim_bench (bench.cpp, accuracy.cpp).
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "bench/contact_accuracy.hpp"
#include "graspsim/engine/model.hpp"

namespace graspsim::bench {

struct Row {
  std::string name;
  int rate = 0;                                        // Hz: physics
  Gyroscopic g = Gyroscopic::kNeglect;
  std::string scheme;                                  // the Integrator: "paper" or "implicit"
  std::string status = "ok";                           // "ok", "unstable: ...", "refused: ..."
  double cost = NAN, cost_min = NAN, cost_max = NAN;   // s wall per s simulated
  double cpu = NAN;                                    // s of this thread's CPU per s simulated
  int repeats = 0;
  double error = 0.0;
  std::string measure;
  // Case details, NaN where they do not apply (empty in the CSV).
  double energy_drift = NAN, momentum_drift = NAN, period = NAN, period_ref = NAN;
  double precession = NAN, precession_ref = NAN;
  std::string note;
};

inline Row make_row(const std::string& name, int rate, Gyroscopic g, Integrator scheme = Model{}.integrator) {
  Row r;
  r.name = name;
  r.rate = rate;
  r.g = g;
  r.scheme = scheme_name(scheme);
  return r;
}

inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

inline double median(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  const std::size_t n = t.size();
  return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

// Times `run` (a whole simulated run of `simulated` s): one warm-up call, dropped, then `repeats`
// timed calls; fills the row's cost (median, min, max wall seconds per simulated second) and
// the median CPU time of this thread per simulated second (less sensitive to a loaded machine:
// time the scheduler gave to other processes is not counted).
template <class Run>
void time_it(Row& row, int repeats, double simulated, Run&& run) {
  using Clock = std::chrono::steady_clock;
  run();   // warm-up: caches, page faults, first allocations
  std::vector<double> t, cpu;
  for (int i = 0; i < repeats; ++i) {
    const double cpu_start = thread_cpu_seconds();
    const auto start = Clock::now();
    run();
    t.push_back(std::chrono::duration<double>(Clock::now() - start).count() / simulated);
    cpu.push_back((thread_cpu_seconds() - cpu_start) / simulated);
  }
  row.cpu = median(cpu);
  row.cost = median(t);
  row.cost_min = *std::min_element(t.begin(), t.end());
  row.cost_max = *std::max_element(t.begin(), t.end());
  row.repeats = repeats;
}

inline std::string num(double v) {
  if (std::isnan(v)) return "";
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

}  // namespace graspsim::bench
