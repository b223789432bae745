// The run loop: devices -> engine -> devices, trace every tick, check expectations on time.
#include "app/run.hpp"

#include <algorithm>
#include <exception>
#include <new>
#include <string>

#include "app/run_loop.hpp"
#include "app/run_trace.hpp"

namespace graspsim::app {

bool RunResult::passed() const {
  return error.empty() &&
         std::all_of(expectations.begin(), expectations.end(), [](const auto& e) { return e.passed; });
}

// The run, stage by stage (app/README.md): each stage is a member of Run (run_loop.cpp), and the
// order below is the order of every tick, which the goldens pin.
RunResult run_scenario(const scripting::Scenario& scenario, const RunOptions& options, const RunSeams& seams) {
  RunResult result;
  RunTrace trace(scenario, options);   // claims the output, opens the trace: throws before anything is written
  Run run(scenario, options, seams, trace, result);
  run.check_stability_before();
  try {
    run.open_devices();   // a device that cannot be built: the run never starts
    run.prepare();
    run.start_pacing();
    for (std::int64_t n = 0; n < run.ticks(); ++n) {
      run.read_devices(n);
      run.capture_initial(n);
      run.check_expectations(n);
      run.step();
      run.render();
      run.pace(n);
      run.record(n);
      run.flush(n);
      run.watch(n);
      run.count();
      run.feed_script(n);
      run.check_interrupt(n);
      run.report_progress(n);
      run.publish_live(n);
    }
    run.after_last_tick();
  } catch (const std::bad_alloc&) {
    // The estimate before the run (run_budget.hpp) leaves room; this is the machine running out
    // anyway (another process took it), said as such rather than as a bare "std::bad_alloc".
    run.fail("out of memory after " + std::to_string(result.servo_ticks) +
             " servo ticks: the machine could not give the run the memory it asked for");
  } catch (const std::exception& e) {
    run.fail(e.what());
  }
  run.stop();
  trace.finish(result, run.started(), run.warnings());
  return result;
}

}  // namespace graspsim::app
