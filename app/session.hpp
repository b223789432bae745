// A run driven one servo tick at a time by the program that holds it (the Python module, an
// embedding application): the same stages in the same order as run_scenario, which is this
// session stepped to its end, so a stepped run writes the trace run_scenario writes, bit for bit.
#pragma once

#include <cstdint>
#include <memory>

#include "app/run.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/simulation.hpp"

namespace graspsim::app {

class Run;
class RunTrace;

class RunSession {
 public:
  // Claims the output and opens the trace, writes the stability estimates, builds every device
  // and prepares the run. Throws as run_scenario does before its first tick (OutputError,
  // recordings::TraceError: nothing written). A device that cannot be built is not thrown: the
  // session is done at once and finish() reports not_started. `scenario` and `options` must
  // outlive the session.
  RunSession(const scripting::Scenario& scenario, const RunOptions& options, const RunSeams& seams = {});
  // Finishes the run if finish() was not called: the trace is closed and renamed, devices released.
  ~RunSession();
  RunSession(const RunSession&) = delete;
  RunSession& operator=(const RunSession&) = delete;

  // Runs servo tick tick(): devices read, expectations due, the engine's step, forces rendered,
  // rows recorded. Returns false (and runs nothing) once done(). An error in the tick (a script
  // error, a device fault, a divergence) ends the run: done() turns true and finish() reports it
  // in RunResult::error.
  bool step();
  bool done() const;
  std::int64_t tick() const { return next_; }     // servo ticks run so far = the next tick's number
  std::int64_t ticks() const;                     // servo ticks of the whole run
  const std::string& error() const { return result_.error; }   // "" while the run is well

  // What the engine holds after the last step (before any: the initial state, empty records).
  const Simulation& simulation() const;
  const TickRecord& record() const;   // the last tick's records (haptic / physics: valid when they ran)
  const Input& input() const;         // the last tick's device inputs (HIP, gimbal per finger)

  // Checks the expectations due at the end (if every tick ran without error), releases every
  // device, finishes the trace. Called before the last tick, it ends the run there, as a run of
  // RunOptions::Stop::max_ticks would: the expectations due at this tick are checked, later ones
  // are reported as not checked, and the trace holds the ticks run. Idempotent: later calls
  // return the same result.
  const RunResult& finish();
  bool finished() const { return finished_; }

 private:
  RunResult result_;
  std::unique_ptr<RunTrace> trace_;
  std::unique_ptr<Run> run_;
  std::int64_t next_ = 0;
  bool stopped_ = false;    // an error ended the run before its last tick
  bool finished_ = false;
};

}  // namespace graspsim::app
