// The benchmark's robustness case: pass rates of perturbed library scenarios per integrator (see
// robustness_case.hpp).
#include "bench/robustness_case.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "bench/robustness.hpp"

namespace graspsim::bench {
namespace {

// One check of one scenario: how many runs of each integrator it held in.
struct Tally {
  std::string check;
  std::map<std::string, int> passed;   // by integrator
};

struct ScenarioTally {
  std::string name;
  std::vector<Tally> checks;                    // expectations in the scenario's order, then the run checks
  std::map<std::string, double> worst;          // m: worst body excursion, by integrator
  std::map<std::string, std::string> worst_run; // the perturbation that gave it

  Tally& check(const std::string& what) {
    for (Tally& t : checks)
      if (t.check == what) return t;
    checks.push_back({what, {}});
    return checks.back();
  }
};

const char* kRan = "ran to its end (no divergence, no script error)";
const char* kFinite = "no NaN or infinity anywhere in the trace";
const char* kInScene = "every body stays in the scene (1 m; floor - 1 cm)";
const char* kSmooth = "no period-2 cycle (a motion reversing every physics step)";

std::string cut(const std::string& text, std::size_t width) {
  return text.size() <= width ? text : text.substr(0, width - 3) + "...";
}

}  // namespace

int run_robustness_case(const RobustnessOptions& o) {
  std::vector<std::string> names = o.scenarios;
  try {
    if (names.empty()) names = robustness::scenarios_with_fingers(o.scenario_dir);
  } catch (const std::exception& e) {
    std::cerr << "graspsim_bench: robustness: " << e.what() << "\n";
    return 2;
  }
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  const std::string scratch = o.out + "/robustness.h5";
  std::vector<ScenarioTally> tallies;
  for (const std::string& name : names) {
    ScenarioTally t;
    t.name = name;
    for (const std::string& integrator : o.integrators) {
      t.worst[integrator] = 0.0;
      for (int seed = 1; seed <= o.seeds; ++seed) {
        robustness::Perturbation p;
        p.jitter = o.jitter;
        p.seed = static_cast<std::uint64_t>(seed);
        p.sets = o.sets;
        p.sets.push_back("integrator=" + integrator);
        robustness::Outcome r;
        try {
          r = robustness::run(o.scenario_dir + "/" + name + ".lua", p, scratch);
        } catch (const std::exception& e) {
          std::cerr << "graspsim_bench: robustness: " << name << ": " << e.what() << "\n";
          return 2;
        }
        for (const auto& e : r.expectations) t.check(e.what).passed[integrator] += e.passed;
        t.check(kRan).passed[integrator] += r.error.empty();
        t.check(kFinite).passed[integrator] += r.nonfinite.empty();
        t.check(kInScene).passed[integrator] += !r.left_scene();
        t.check(kSmooth).passed[integrator] += !r.period_two();
        if (!(r.worst_excursion() <= t.worst[integrator])) {
          t.worst[integrator] = r.worst_excursion();
          t.worst_run[integrator] = r.label;
        }
      }
      std::fprintf(stderr, "  robustness: %s, integrator %s: done\n", name.c_str(), integrator.c_str());
    }
    tallies.push_back(t);
  }

  // ---- output -------------------------------------------------------------------------------
  char amplitude[32];
  std::snprintf(amplitude, sizeof amplitude, "%g", o.jitter * 1e3);
  std::string extra;
  for (const std::string& s : o.sets) extra += " --set " + s;
  std::printf("\nrobustness: %d seeds of +-%s mm waypoint jitter per scenario, at its own rates%s; "
              "pass rate of each check\n", o.seeds, amplitude, extra.c_str());
  std::printf("%-62s", "scenario / check");
  for (const std::string& i : o.integrators) std::printf(" %9s", i.c_str());
  std::printf("\n");
  const std::string csv_path = o.out + "/robustness.csv";
  std::ofstream csv(csv_path);
  csv << "scenario,integrator,check,passed,runs,value\n";
  for (const ScenarioTally& t : tallies) {
    std::printf("%s\n", t.name.c_str());
    for (const Tally& c : t.checks) {
      std::printf("  %-60s", cut(c.check, 60).c_str());
      for (const std::string& i : o.integrators) {
        const auto it = c.passed.find(i);
        const int passed = it == c.passed.end() ? 0 : it->second;
        std::printf(" %8.0f%%", 100.0 * passed / o.seeds);
        std::string quoted = c.check;
        for (char& ch : quoted)
          if (ch == '"') ch = '\'';
        csv << t.name << ',' << i << ",\"" << quoted << "\"," << passed << ',' << o.seeds << ",\n";
      }
      std::printf("\n");
    }
    std::printf("  %-60s", "worst body excursion (m)");
    for (const std::string& i : o.integrators) {
      std::printf(" %9.4g", t.worst.at(i));
      csv << t.name << ',' << i << ",worst body excursion m,,," << t.worst.at(i) << "\n";
    }
    std::printf("\n");
    for (const std::string& i : o.integrators)
      if (t.worst_run.count(i)) std::printf("    %s: worst in %s\n", i.c_str(), t.worst_run.at(i).c_str());
  }
  std::printf("\nwrote %s\n", csv_path.c_str());
  return 0;
}

}  // namespace graspsim::bench
