// Real-time profile (engine/README.md, "Speed"): per-tick wall time of the servo, haptic and
// physics loops for a three-finger grasp of a 5,120-triangle mesh
// (tools/bench/mesh_grasp_scene.hpp), with the engine alone (no Lua, no trace, no device). Each
// Simulation::step call is timed with steady_clock around it (the clock stays out of engine/) and
// filed by which loops ran in it:
//   servo     a tick with the servo loop only (finger forces)
//   +haptic   a tick where the haptic loop ran too (entry, walk, friction cone), no physics
//   +physics  a tick where all three ran (body contact, floor, integration, broadphase update)
// and the table gives, per kind, the count, median, 99th percentile and max in microseconds over
// all repeats (the first run, a warm-up, is dropped). Sleep off and on are interleaved run by run.
// Not a test (tests never time things): run it by hand, on a quiet machine, pinned if you can:
//   taskset -c 1 ./build/tools/graspsim_profile [REPEATS]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <string>
#include <vector>

#include "graspsim/engine/simulation.hpp"
#include "graspsim/engine/state_hash.hpp"
#include "bench/mesh_grasp_scene.hpp"

using namespace graspsim;

namespace {

struct Samples {
  std::vector<double> servo, haptic, physics, all;   // us per step
};

double percentile(std::vector<double> v, double p) {   // nearest rank
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t k = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, k == 0 ? 0 : k - 1)];
}

struct Outcome {
  double lift = 0.0;            // m: pebble's rise at the end
  std::uint64_t hash = 0;       // state_hash at the end
};

Outcome run_once(const Model& model, Samples* samples) {
  Simulation sim(model);
  Input input = make_input(model);
  TickRecord record = make_tick_record(model);
  const std::int64_t ticks = static_cast<std::int64_t>(bench::kSceneDuration * model.rates.servo);
  const double z0 = sim.state().bodies[0].position.z();
  Outcome out;
  for (std::int64_t n = 0; n < ticks; ++n) {
    bench::mesh_grasp_hips(sim.time(), input);
    const auto t0 = std::chrono::steady_clock::now();
    sim.step(input, record);
    const auto t1 = std::chrono::steady_clock::now();
    if (samples) {
      const double us = std::chrono::duration<double, std::micro>(t1 - t0).count();
      (record.physics_ran ? samples->physics : record.haptic_ran ? samples->haptic : samples->servo).push_back(us);
      samples->all.push_back(us);
    }
  }
  out.lift = sim.state().bodies[0].position.z() - z0;
  out.hash = state_hash(sim.state());
  return out;
}

void print_row(const char* name, const std::vector<double>& v) {
  std::printf("  %-10s %8zu %9.2f %9.2f %9.2f\n", name, v.size(), percentile(v, 0.5), percentile(v, 0.99),
              v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()));
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  struct Variant {
    const char* name;
    Model model;
    Samples samples;
    Outcome outcome;
  };
  std::vector<Variant> variants;
  for (bool sleep : {false, true}) {
    Model m = bench::mesh_grasp_model();
    m.sleep.enabled = sleep;   // SLEEP
    variants.push_back(Variant{sleep ? "sleep on" : "sleep off", m, {}, {}});
  }
  for (int r = 0; r <= repeats; ++r) {   // run 0 warms up and is dropped
    for (Variant& v : variants) v.outcome = run_once(v.model, r == 0 ? nullptr : &v.samples);
  }
  const Model& model = variants[0].model;
  std::printf("graspsim_profile: three fingers grasp a %zu-triangle mesh, %.1f s at %d / %d / %d Hz, %d repeats\n",
              model.bodies[0].shape.mesh->triangles.size(), bench::kSceneDuration, model.rates.servo,
              model.rates.haptic, model.rates.physics, repeats);
  for (const Variant& v : variants) {
    std::printf("%s: pebble lifted %.1f mm; final state_hash %016llx; mean run %.1f ms (sum of its steps)\n", v.name,
                1e3 * v.outcome.lift, static_cast<unsigned long long>(v.outcome.hash),
                1e-3 * std::accumulate(v.samples.all.begin(), v.samples.all.end(), 0.0) / repeats);
    std::printf("  %-10s %8s %9s %9s %9s   (us per Simulation::step)\n", "ticks", "count", "median", "p99", "max");
    print_row("servo", v.samples.servo);
    print_row("+haptic", v.samples.haptic);
    print_row("+physics", v.samples.physics);
    print_row("all", v.samples.all);
  }
  return 0;
}
