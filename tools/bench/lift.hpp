// d) The paper's two-finger lift (scenarios/two_finger_lift.lua) through scripting::Scenario,
// fingers scripted, at a given physics rate and gyroscopic option (the scenario's other rates).
#pragma once

#include <vector>

#include "graspsim/engine/model.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::bench {

struct LiftResult {
  bool diverged = false;
  std::vector<Vec3> samples;   // m, world: the box's centre at every 1/50 s from t = 0 (the
                               //    physics rows at those ticks: the same instants at every rate)
};

// Runs the scenario's first body and fingers for its duration; `result` is reused between runs
// (its buffer is reserved once).
void run_lift(const scripting::Scenario& scenario, int physics_rate, Gyroscopic g, LiftResult& result);

// Largest distance (m) between two runs' samples at the same instants; infinity when one run is
// shorter (it diverged).
double max_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b);

}  // namespace graspsim::bench
