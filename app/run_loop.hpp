// The stages of one run, each a member of Run, which holds what they share. RunSession (run.cpp,
// session.hpp) calls them in order and is the table of contents; this header is for run.cpp and
// run_loop.cpp only.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/device_tables.hpp"
#include "app/expectation_schedule.hpp"
#include "app/run.hpp"
#include "app/run_trace.hpp"
#include "app/script_thread.hpp"
#include "app/stability_watch.hpp"
#include "graspsim/engine/energy.hpp"
#include "graspsim/engine/simulation.hpp"
#include "graspsim/hw/sample_check.hpp"

namespace graspsim::app {

class Run {
 public:
  Run(const scripting::Scenario& scenario, const RunOptions& options, const RunSeams& seams, RunTrace& trace,
      RunResult& result);
  Run(const Run&) = delete;
  Run& operator=(const Run&) = delete;

  // Before the loop.
  void check_stability_before();   // the model's estimates, written to the trace before the run
  void open_devices();             // every finger's device (and the script thread's feeds)
  void prepare();                  // simulation, tables, expectations, views, the script thread
  void start_pacing();             // real-time thread, Lua forbidden here, tick 0's period begins
  std::int64_t ticks() const { return run_ticks_; }

  // One servo tick, in this order.
  void read_devices(std::int64_t n);
  void capture_initial(std::int64_t n);   // tick 0: the state expectations compare with
  void check_expectations(std::int64_t n) { expectations_->at_tick(n, *sim_, record_, slip_); }
  void step() { sim_->step(input_, record_); }
  void render();                          // forces to every device
  void pace(std::int64_t n);              // wait for the deadline; a stall releases and throws
  void record(std::int64_t n);            // /devices rows, then one row per loop that ran
  void flush(std::int64_t n) { trace_.flush_if_due(n); }
  void watch(std::int64_t n);             // divergence, instability, energy gain: throw to stop
  void count();                           // ticks, slip
  void feed_script(std::int64_t n);       // views for Lua trajectories, tick done
  void check_interrupt(std::int64_t n);   // throws when interrupted
  void report_progress(std::int64_t n);
  void publish_live(std::int64_t n);      // the live view's snapshot, after a haptic or physics tick

  // After the loop.
  // After servo tick n - 1, the last one run (n = ticks() unless the stepping program stopped
  // sooner): a run of no tick: its initial state; the expectations due at tick n.
  void after_last_tick(std::int64_t n);
  void fail(const std::string& error) { result_.error = error; }
  void stop();                     // release every device, leave real time, deferred checks
  bool started() const { return started_; }
  // What a stepping program reads between ticks (RunSession): null before prepare().
  const Simulation* simulation() const { return sim_ ? &*sim_ : nullptr; }
  const TickRecord& tick_record() const { return record_; }
  const Input& input() const { return input_; }
  std::string warnings() const { return stability_.text(); }

 private:
  void release_all();

  const scripting::Scenario& scenario_;
  const Model& model_;
  const RunOptions& options_;
  const RunSeams& seams_;
  RunTrace& trace_;
  RunResult& result_;
  const bool paced_;
  const RunClock::time_point start_;
  RunClock::time_point last_progress_;
  std::int64_t run_ticks_ = 0;
  double tick_time_ = 0.0;         // s: the tick under way's time, before its step
  TickPace tick_pace_;             // how the tick under way kept its deadline

  std::vector<std::unique_ptr<hw::Device>> devices_;
  std::string release_error_;      // a device that failed to take zero force, if the run has no error
  // Paced runs keep Lua off the loop's thread (script_thread.hpp, README.md "Devices"): Lua
  // trajectories are sampled ahead on a script thread, declared after the devices so that it
  // stops before they go.
  std::optional<ScriptThread> script_;
  bool script_feeds_ = false;
  std::vector<hw::SampleCheck> checks_;                      // finite, inside the workspace
  std::vector<hw::DeviceSample> samples_;                    // this tick's, as read (world)
  std::vector<std::unique_ptr<hw::Trajectory>> side_scripts_;   // RunOptions::Devices::script_alongside
  std::vector<Vec3> rendered_;                               // N, world: what each device rendered

  StabilityWatch stability_;
  EnergyWatch energy_;             // a blow-up of bodies nothing powers stops the run (energy.hpp)
  std::optional<Simulation> sim_;
  Input input_;
  TickRecord record_;
  std::vector<double> slip_;       // m: each finger's god-object slide so far
  DeviceTables device_tables_;
  std::optional<ExpectationSchedule> expectations_;
  // The read-only view trajectory functions get: the state as the last physics tick left it.
  bool view_ = false;
  scripting::Snapshot view_state_;
  std::int64_t live_physics_tick_ = -1, live_haptic_tick_ = -1;   // servo ticks the live snapshot's parts are from
  bool realtime_ = false;          // this thread is SCHED_FIFO (until stop())
  bool started_ = false;           // every device was built: the run goes on to its first tick
};

}  // namespace graspsim::app
