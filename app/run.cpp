// The run loop: devices -> engine -> devices, trace every tick, check expectations on time.
#include "app/run.hpp"

#include <algorithm>
#include <exception>
#include <new>
#include <stdexcept>
#include <string>

#include "app/run_loop.hpp"
#include "app/run_trace.hpp"
#include "app/session.hpp"

namespace graspsim::app {

bool RunResult::passed() const {
  return error.empty() &&
         std::all_of(expectations.begin(), expectations.end(), [](const auto& e) { return e.passed; });
}

namespace {

// The message of an exception that ends the run.
std::string failure(std::int64_t servo_ticks) {
  try {
    throw;
  } catch (const std::bad_alloc&) {
    // The estimate before the run (run_budget.hpp) leaves room; this is the machine running out
    // anyway (another process took it), said as such rather than as a bare "std::bad_alloc".
    return "out of memory after " + std::to_string(servo_ticks) +
           " servo ticks: the machine could not give the run the memory it asked for";
  } catch (const std::exception& e) {
    return e.what();
  }
}

}  // namespace

// The run, stage by stage (app/README.md): each stage is a member of Run (run_loop.cpp). The
// constructor holds what comes before the loop, step() the order of every tick, which the
// goldens pin, and finish() what comes after.
RunSession::RunSession(const scripting::Scenario& scenario, const RunOptions& options, const RunSeams& seams) {
  // Claims the output, opens the trace: throws before anything is written.
  trace_ = std::make_unique<RunTrace>(scenario, options);
  run_ = std::make_unique<Run>(scenario, options, seams, *trace_, result_);
  run_->check_stability_before();
  try {
    run_->open_devices();   // a device that cannot be built: the run never starts
    run_->prepare();
    run_->start_pacing();
  } catch (...) {
    run_->fail(failure(result_.servo_ticks));
    stopped_ = true;
  }
}

RunSession::~RunSession() {
  try {
    finish();
  } catch (...) {
    // A destructor must not throw; finish() keeps what failed in the result, which nobody reads now.
  }
}

bool RunSession::done() const { return finished_ || stopped_ || next_ >= run_->ticks(); }
std::int64_t RunSession::ticks() const { return run_->ticks(); }

bool RunSession::step() {
  if (done()) return false;
  const std::int64_t n = next_;
  try {
    run_->read_devices(n);
    run_->capture_initial(n);
    run_->check_expectations(n);
    run_->step();
    run_->render();
    run_->pace(n);
    run_->record(n);
    run_->flush(n);
    run_->watch(n);
    run_->count();
    run_->feed_script(n);
    run_->publish_live(n);   // before a stop can end the run: the view's last tick is the trace's
    run_->check_interrupt(n);
    run_->report_progress(n);
  } catch (...) {
    run_->fail(failure(result_.servo_ticks));
    stopped_ = true;
  }
  ++next_;
  return true;
}

const Simulation& RunSession::simulation() const {
  if (!run_->simulation()) throw std::logic_error("the run did not start: " + result_.error);
  return *run_->simulation();
}
const TickRecord& RunSession::record() const { return run_->tick_record(); }
const Input& RunSession::input() const { return run_->input(); }

const RunResult& RunSession::finish() {
  if (finished_) return result_;
  finished_ = true;
  if (!stopped_) {
    try {
      run_->after_last_tick(next_);
    } catch (...) {
      run_->fail(failure(result_.servo_ticks));
    }
  }
  run_->stop();
  trace_->finish(result_, run_->started(), run_->warnings());
  return result_;
}

RunResult run_scenario(const scripting::Scenario& scenario, const RunOptions& options, const RunSeams& seams) {
  RunSession session(scenario, options, seams);
  while (session.step()) {
  }
  return session.finish();
}

}  // namespace graspsim::app
