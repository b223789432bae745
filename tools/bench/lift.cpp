// d) The two-finger lift: see lift.hpp.
#include "bench/lift.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

#include "graspsim/engine/record.hpp"
#include "graspsim/engine/simulation.hpp"
#include "graspsim/hw/trajectory.hpp"

namespace graspsim::bench {

void run_lift(const scripting::Scenario& scenario, int rate, Gyroscopic g, LiftResult& result) {
  Model model = scenario.model();
  model.rates.physics = rate;
  model.gyroscopic = g;
  std::vector<std::unique_ptr<hw::Trajectory>> fingers;
  for (std::size_t f = 0; f < model.fingers.size(); ++f) fingers.push_back(scenario.make_trajectory(f));
  Simulation sim(model);
  Input input = make_input(model);
  TickRecord record = make_tick_record(model);
  const std::int64_t ticks = std::llround(scenario.duration() * model.rates.servo);
  const std::int64_t every = model.rates.servo / 50;   // servo ticks per 1/50 s
  result.diverged = false;
  result.samples.clear();
  result.samples.reserve(static_cast<std::size_t>(ticks / every) + 1);
  for (std::int64_t n = 0; n < ticks; ++n) {
    const double t = sim.time();
    for (std::size_t f = 0; f < fingers.size(); ++f) {
      const hw::TrajectorySample s = fingers[f]->sample(t);
      input.fingers[f].hip = s.position;
      input.fingers[f].gimbal = s.gimbal;
    }
    sim.step(input, record);
    if (record.diverged_body >= 0) {
      result.diverged = true;
      return;
    }
    if (n % every == 0) result.samples.push_back(record.physics[0].position);
  }
}

double max_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return std::isfinite(d) ? d : std::numeric_limits<double>::infinity();
}

}  // namespace graspsim::bench
