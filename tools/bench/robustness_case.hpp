// The benchmark's robustness case (graspsim_bench --cases robustness; tools/bench/README.md):
// every library scenario with fingers, N seeds of waypoint jitter each, at the scenario's own
// rates, under each integrator; per scenario the pass rate of each expectation, of "ran to its
// end", "no NaN" and "stayed in the scene", and the worst body excursion, as a table and a CSV.
// Measured, not timed.
#pragma once

#include <string>
#include <vector>

namespace graspsim::bench {

struct RobustnessOptions {
  int seeds = 100;                    // jitter seeds 1..seeds per scenario and integrator
  double jitter = 0.5e-3;             // m: offset amplitude per axis
  std::vector<std::string> integrators{"paper", "implicit"};   // `--set integrator=...` per column
  std::vector<std::string> sets;      // more --set overrides for every run (e.g. rates.physics=100)
  std::vector<std::string> scenarios; // scenario stems to run; empty: every one with fingers
  std::string scenario_dir;           // where the scenarios are
  std::string out;                    // directory for robustness.csv and the scratch traces
};

// Prints the table and writes OUT/robustness.csv; returns 0, or 2 when a scenario does not load.
int run_robustness_case(const RobustnessOptions& options);

}  // namespace graspsim::bench
