// The stability check over a run (engine/stability.hpp): the model's estimates before it, the
// coupled-mode analysis after every physics tick whose contact set changed, each warning given
// once with its simulated time and kept for the trace, and, when asked, a refusal.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspsim/engine/stability.hpp"

namespace graspsim::app {

// Thrown by StabilityWatch::after_physics when it refuses to go on: its message names the mode.
class StabilityRefusal : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class StabilityWatch {
 public:
  // `refuse`: an unstable mode stops the run (stability = "refuse", --refuse-unstable);
  // `on_warning` (may be empty) receives each warning line as it is given.
  StabilityWatch(const Model& model, bool refuse, std::function<void(const std::string&)> on_warning);

  // The points of touching pairs from the run's own gather (Simulation::contacts()) from now on.
  void use_contacts(ContactGather& contacts) { monitor_.use_contacts(contacts); }

  // The model's estimates (stability_warnings), before the run: warnings, never a refusal.
  void before_run();

  // After the physics step of servo tick `tick` (at `time` s), under the paper's scheme: analyses
  // the state again if its contact set changed. Returns true when it added a warning; when
  // refusing, throws StabilityRefusal after adding it.
  bool after_physics(const State& state, std::int64_t tick, double time);

  // Every warning so far, one line each: the estimates as they are, the run's as
  // "t = T s (tick N): ...".
  const std::vector<std::string>& lines() const { return lines_; }
  std::string text() const;   // the lines joined, each ended by a newline

 private:
  const Model& model_;
  bool refuse_;
  std::function<void(const std::string&)> on_warning_;
  StabilityMonitor monitor_;
  std::vector<std::string> lines_;
  void add(const std::string& line);
};

}  // namespace graspsim::app
