// The stability check over a run (stability_watch.hpp).
#include "app/stability_watch.hpp"

#include <cstdio>

namespace graspsim::app {

StabilityWatch::StabilityWatch(const Model& model, bool refuse, std::function<void(const std::string&)> on_warning)
    : model_(model), refuse_(refuse), on_warning_(std::move(on_warning)), monitor_(model) {}

void StabilityWatch::add(const std::string& line) {
  lines_.push_back(line);
  if (on_warning_) on_warning_(line);
}

void StabilityWatch::before_run() {
  for (const std::string& w : stability_warnings(model_)) add(w);
}

bool StabilityWatch::after_physics(const State& state, std::int64_t tick, double time) {
  // Only the paper's explicit step can be unstable: the implicit map's radius is below 1 for any
  // stiffness, damping and rate (tests/engine/test_stability.cpp), so its runs, paced ones
  // above all, spend nothing on the analysis.
  if (model_.integrator != Integrator::kPaper) return false;
  const std::string warning = monitor_.update(state);
  if (warning.empty()) return false;
  char when[64];
  std::snprintf(when, sizeof when, "t = %.3f s (tick %lld): ", time, static_cast<long long>(tick));
  add(when + warning);
  if (refuse_) {
    throw StabilityRefusal("the stability check refused to go on: " + lines_.back());
  }
  return true;
}

std::string StabilityWatch::text() const {
  std::string out;
  for (const std::string& l : lines_) out += l + "\n";
  return out;
}

}  // namespace graspsim::app
