// A library scenario on the engine alone: loaded through scripting, its fingers fed from their
// scripted trajectories tick by tick, with no devices, trace or expectations (those are the run
// loop's, app/). For tests that need a scenario's contact set or its whole run.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "graspsim/engine/simulation.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::test {

inline std::string scenario_path(const std::string& name) {
  return std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/" + name + ".lua";
}

inline scripting::Scenario load_scenario(const std::string& name, const std::vector<std::string>& sets = {}) {
  scripting::LoadOptions options;
  options.sets = sets;
  return scripting::Scenario::load(scenario_path(name), options);
}

// A finger's HIP offset (m, world) at time t (s), added to its scripted trajectory.
using HipOffset = std::function<Vec3(std::size_t finger, double t)>;

// Runs `scenario` on `sim` (built from its model) up to servo tick `ticks`; `after` sees the
// simulation after every tick that ran a physics step and may stop the run by returning false.
// Trajectories that read the view get what the run loop gives them (app/run_loop.cpp), after
// each physics step.
inline void drive(const scripting::Scenario& scenario, Simulation& sim, std::int64_t ticks,
                  const std::function<bool(const Simulation&)>& after = {}, const HipOffset& offset = {}) {
  const Model& model = sim.model();
  std::vector<std::unique_ptr<hw::Trajectory>> hands;
  for (std::size_t f = 0; f < model.fingers.size(); ++f) hands.push_back(scenario.make_trajectory(f));
  Input input = make_input(model);
  TickRecord record = make_tick_record(model);
  std::vector<double> slip(model.fingers.size(), 0.0);
  scripting::Snapshot view;
  const auto update_view = [&] {
    if (!scenario.uses_view()) return;
    scripting::fill_snapshot(sim, record, slip, view);
    scenario.update_view(view);
  };
  update_view();
  while (sim.tick() < ticks) {
    const double t = sim.time();
    for (std::size_t f = 0; f < hands.size(); ++f) {
      const hw::TrajectorySample s = hands[f]->sample(t);
      input.fingers[f].hip = offset ? Vec3(s.position + offset(f, t)) : s.position;
      input.fingers[f].gimbal = s.gimbal;
    }
    sim.step(input, record);
    if (record.haptic_ran) {
      for (std::size_t f = 0; f < slip.size(); ++f) slip[f] += record.haptic[f].slip;
    }
    if (!record.physics_ran) continue;
    update_view();
    if (after && !after(sim)) return;
  }
}

}  // namespace graspsim::test
