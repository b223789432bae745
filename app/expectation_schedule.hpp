// The scenario's expectations, checked at their ticks: one scheduler for paced and unpaced runs.
// Each falls due at tick round(at * rate_servo) (at < 0, or past the end: the scenario's last
// tick), ties in the scenario's order. Unpaced, each is checked at its tick on the loop's thread,
// so a script error stops the run there and the Lua state sees the checks in the tick's fixed
// order (the goldens pin it). Deferred (a paced run, README.md "Devices"), the loop only copies
// the snapshot into a slot sized before the loop (no allocation, no Lua) and the checks run after
// the loop, in due order, once the thread may enter Lua again.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "graspsim/engine/simulation.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::app {

class ExpectationSchedule {
 public:
  // `end_tick`: the scenario's last servo tick (duration * rate_servo). Every result starts as
  // "not checked: the run stopped before it was due" in `results`, which must outlive this.
  ExpectationSchedule(const scripting::Scenario& scenario, std::int64_t end_tick, bool deferred,
                      std::vector<scripting::ExpectationResult>& results);
  // Deferred: room in every slot (and the initial snapshot) for a state like `prototype`.
  void presize(const scripting::Snapshot& prototype);
  // The state at t = 0 that every check compares with.
  void capture_initial(const Simulation& sim, const TickRecord& record, const std::vector<double>& slip);
  // The expectations due at tick n: checked now (a script error throws), or copied for later.
  void at_tick(std::int64_t n, const Simulation& sim, const TickRecord& record, const std::vector<double>& slip);
  // Deferred: checks every copy taken, in due order; throws a script error. Unpaced: nothing.
  void check_deferred();

 private:
  const scripting::Scenario& scenario_;
  bool deferred_;
  std::vector<scripting::ExpectationResult>& results_;
  std::vector<std::pair<std::int64_t, std::size_t>> due_;   // (tick, expectation) in due order
  std::size_t next_ = 0;                                    // the next due_ entry
  std::vector<scripting::Snapshot> slots_;                  // deferred: the snapshot at each due tick
  scripting::Snapshot initial_;
};

}  // namespace graspsim::app
