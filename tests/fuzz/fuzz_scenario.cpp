// libFuzzer harness: the scenario loader, Lua text in (README.md "Sanitizers and fuzzing").
// Property: any text either loads or is refused with a ScenarioError (the loader's one
// exception, scripting/error.hpp); a scenario that loads gives a model the engine either accepts
// or refuses with std::invalid_argument (engine/simulation.hpp), and the accepted one steps for
// one physics period with its fingers on their trajectories. Anything else (a crash, a sanitizer
// finding, another exception, a hang past libFuzzer's -timeout, memory past -rss_limit_mb) is a
// finding.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspsim/engine/simulation.hpp"
#include "graspsim/scripting/error.hpp"
#include "graspsim/scripting/scenario.hpp"

using namespace graspsim;

namespace {

// Lower than a run's limits (256 MiB, 2e8 instructions) so one input takes milliseconds, not
// seconds; the same budget and allocator code refuses both. 2e6 instructions: 9 to 20 ms here.
scripting::LoadOptions fuzz_options() {
  scripting::LoadOptions options;
  options.limits.memory_mib = 64;
  options.limits.load_instructions = 2'000'000;
  options.limits.call_instructions = 200'000;
  return options;
}

// Steps the engine through its first two physics steps (servo ticks 0 to one physics period, at
// most 601 ticks) with every finger at its trajectory's sample, as the run loop does without
// devices.
void step_one_physics_period(const scripting::Scenario& scenario) {
  Simulation sim(scenario.model());
  const Model& model = sim.model();
  std::vector<std::unique_ptr<hw::Trajectory>> hands;
  for (std::size_t f = 0; f < model.fingers.size(); ++f) hands.push_back(scenario.make_trajectory(f));
  Input input = make_input(model);
  TickRecord record = make_tick_record(model);
  const std::int64_t ticks = std::min<std::int64_t>(sim.divisors().physics + 1, 601);
  while (sim.tick() < ticks) {
    for (std::size_t f = 0; f < hands.size(); ++f) {
      const hw::TrajectorySample s = hands[f]->sample(sim.time());
      input.fingers[f].hip = s.position;
      input.fingers[f].gimbal = s.gimbal;
    }
    sim.step(input, record);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string source(reinterpret_cast<const char*>(data), size);
  // Relative mesh names resolve against the library's own scenarios/ (meshes/*.obj, *.stl).
  const std::string path = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/fuzz_input.lua";
  std::unique_ptr<scripting::Scenario> scenario;
  try {
    scenario = std::make_unique<scripting::Scenario>(scripting::Scenario::load_source(source, path, fuzz_options()));
  } catch (const scripting::ScenarioError&) {
    return 0;   // refused with a message: the promised outcome for bad text
  }
  try {
    step_one_physics_period(*scenario);
  } catch (const std::invalid_argument&) {
    return 0;   // the engine refused the model, naming the field
  } catch (const scripting::ScenarioError&) {
    return 0;   // a trajectory's Lua raised or ran out of budget: the run stops with its message
  }
  return 0;
}
