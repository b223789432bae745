// Expectations at their ticks, checked now or after the loop (expectation_schedule.hpp).
#include "app/expectation_schedule.hpp"

#include <algorithm>
#include <cmath>

#include "app/script_thread.hpp"

namespace graspsim::app {

ExpectationSchedule::ExpectationSchedule(const scripting::Scenario& scenario, std::int64_t end_tick, bool deferred,
                                         std::vector<scripting::ExpectationResult>& results)
    : scenario_(scenario), deferred_(deferred), results_(results) {
  const int rate = scenario.model().rates.servo;
  for (std::size_t i = 0; i < scenario.expectations().size(); ++i) {
    const double at = scenario.expectations()[i].at;
    const std::int64_t tick = at < 0.0 ? end_tick : std::min<std::int64_t>(end_tick, std::llround(at * rate));
    due_.emplace_back(tick, i);
  }
  std::sort(due_.begin(), due_.end());
  for (const auto& e : scenario.expectations())
    results_.push_back({e.what, false, "not checked: the run stopped before it was due"});
}

void ExpectationSchedule::presize(const scripting::Snapshot& prototype) {
  if (!deferred_) return;
  slots_.assign(due_.size(), prototype);
  for (scripting::Snapshot& s : slots_) presize_snapshot(s);
  initial_ = prototype;
  presize_snapshot(initial_);
}

void ExpectationSchedule::capture_initial(const Simulation& sim, const TickRecord& record,
                                          const std::vector<double>& slip) {
  if (deferred_) {
    scripting::fill_snapshot(sim, record, slip, initial_);   // into the room presize() made
  } else {
    scripting::Snapshot s;
    scripting::fill_snapshot(sim, record, slip, s);
    initial_ = std::move(s);
  }
}

void ExpectationSchedule::at_tick(std::int64_t n, const Simulation& sim, const TickRecord& record,
                                  const std::vector<double>& slip) {
  while (next_ < due_.size() && due_[next_].first == n) {
    const std::size_t i = due_[next_].second;
    if (deferred_) {
      scripting::fill_snapshot(sim, record, slip, slots_[next_]);
    } else {
      scripting::Snapshot now;
      scripting::fill_snapshot(sim, record, slip, now);
      results_[i] = scenario_.check(i, now, initial_);
    }
    ++next_;
  }
}

void ExpectationSchedule::check_deferred() {
  if (!deferred_) return;
  for (std::size_t k = 0; k < next_; ++k) {
    const std::size_t i = due_[k].second;
    results_[i] = scenario_.check(i, slots_[k], initial_);
  }
}

}  // namespace graspsim::app
