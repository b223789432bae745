// Running a scenario: devices feed the engine tick by tick, every tick is traced, and the
// scenario's expectations are checked at their times. Lives outside engine/ because it owns the
// wall clock (for the real-time factor and the progress line), the devices and the trace.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "app/live_channel.hpp"
#include "app/output_file.hpp"
#include "app/pacer.hpp"
#include "graspsim/hw/device.hpp"
#include "graspsim/recordings/record_selection.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::app {

// What one run writes, reads and is driven by, grouped by concern. The defaults run the
// scenario's own scripts as fast as possible into a trace named after the scenario.
struct RunOptions {
  // Trace path; "" means default_trace_name(scenario name) in the working directory. The trace
  // is written as "<out>.partial", locked, and renamed to `out` when the run ends (output_file.hpp).
  std::string out;
  // Files the run reads besides the scenario and its mesh files (which run_scenario adds): a
  // device's replay recording, the trace replayed. The output may be none of them.
  std::vector<InputFile> inputs;
  // The --set overrides as given (NAME=VALUE, "duration=S" for --duration), for the trace's
  // `overrides` attribute: with the scenario source they reload the same scenario (replay).
  std::vector<std::string> overrides;
  std::vector<std::pair<std::string, std::string>> attributes;   // extra root string attributes (`replay_of`)

  // How the trace is written (recordings/README.md "Cost").
  struct Trace {
    bool write = true;                // false: no trace at all (--no-trace; the logging benchmark's baseline)
    // true: HDF5 writing runs on a writer thread (TraceOptions::background); false: on the run
    // loop's thread (the logging benchmark compares the two). The file is the same.
    bool background_writer = true;
    std::size_t block_rows = 0;       // trace rows buffered per loop before a write, = rows per
                                      // chunk; 0: one flush interval of that loop (run_trace.cpp)
    int compression = 0;              // 0 none, 1..9 deflate level
    // The loops written and how often (--record; root attribute `record`): default every loop
    // at every tick. Replay needs /servo (and /devices, where a device was recorded) at every tick.
    recordings::RecordSelection record;
    // How messages name the output and say how to write none: `--out` and `--no-trace` for the
    // CLI's run; a replay or the Python module say their own.
    OutputNaming naming;
  } trace;

  // What drives each finger, and what of it is recorded (README.md "Devices").
  struct Devices {
    // The device of finger f instead of its scripted trajectory (empty: scripted).
    std::function<std::unique_ptr<hw::Device>(std::size_t finger)> make;
    // Fingers whose every device sample goes to /devices/<finger> (empty: none; the fingers of
    // non-scripted devices, DevicePlan::recorded()).
    std::vector<bool> record;
    // Whether /devices tables get the `sequence` and `new_samples` columns (false: a replay of a
    // trace whose tables lack them, so that the replay can equal it).
    bool counters = true;
    // Fingers whose device does not run the finger's script itself (udp, phantom; empty: none,
    // DevicePlan::script_alongside()): the run evaluates that script at every tick before the
    // device is read, its output discarded, as a replay: device does, so a script that watches
    // the run (or draws from math.random) sees the same whatever drives the finger, and a session
    // replays bit for bit. In a paced run the script thread computes it (no Lua on the loop).
    std::vector<bool> script_alongside;
  } devices;

  // Real-time pacing (pacer.hpp), with a real device attached: a null pacer runs as fast as
  // possible. With a pacer the loop prints nothing (no progress callback) and checks the
  // interrupt at every tick; a stall releases every device and stops the run. `realtime`: the
  // loop's thread asks for SCHED_FIFO while it runs (after the trace writer's thread started, so
  // that thread stays an ordinary one).
  struct Pacing {
    Pacer* pacer = nullptr;
    bool realtime = false;
  } pacing;

  // The live view (live_channel.hpp): when set, after every tick that ran the haptic or the
  // physics loop the loop copies the bodies' poses and the fingers' HIP, god-object, force and
  // contact into the channel's preallocated snapshot and publishes it (no lock, no allocation;
  // the trace is the same with or without it). Sized for the scenario's model: a channel of
  // other sizes ends the run before its first tick, with an error saying so.
  LiveChannel* live = nullptr;

  // When the run stops before the scenario's end.
  struct Stop {
    const std::atomic<bool>* interrupt = nullptr;   // set (by a signal handler) to stop the run
    const std::atomic<int>* signal = nullptr;       // the signal that set it, for the message (0: none)
    // At most this many servo ticks (< 0: the scenario's duration; expectations due later are
    // reported as not checked): a replay of a trace cut short.
    std::int64_t max_ticks = -1;
  } stop;

  // What the run tells as it goes.
  struct Report {
    // Called every 0.25 s of wall time, once a run has taken 2 s, with the simulated time reached
    // (s); may be empty. Never in a paced run.
    std::function<void(double simulated, double duration)> progress;
    // The stability check (engine/stability.hpp, stability_watch.hpp): each warning line, before
    // the run and as the run finds an unstable mode (with its simulated time), goes to
    // `on_warning` (may be empty) and into the trace's `warnings`. `refuse_unstable` (or the
    // scenario's stability = "refuse") stops the run at the first unstable mode, with an error
    // naming it. The analysis runs on the loop's thread when the contact set changes (tens to
    // hundreds of microseconds), so in a paced run such a tick may be late.
    std::function<void(const std::string& warning)> on_warning;
    bool refuse_unstable = false;
  } report;
};

// Seams for tests, apart from the user's options. `wait_for_script`: in a paced run the loop
// waits for a Lua trajectory sample the script thread can still compute instead of holding the
// last one (ScriptThreadOptions::wait_for_samples), so a paced run on a fake clock, which
// outruns any thread, gets every sample. Never with a hand on a device.
struct RunSeams {
  bool wait_for_script = false;
};

// Servo ticks between two flushes of the trace on simulated time (about 0.25 s): also every
// table's block and chunk, in rows of its loop (run_trace.cpp; run_budget.hpp counts on it).
std::int64_t flush_interval_ticks(const Model& model);

struct RunResult {
  std::string trace_path;   // where the trace is; "" when nothing was written (the run did not start)
  std::vector<scripting::ExpectationResult> expectations;
  std::vector<std::string> warnings;   // stability warnings: the model's estimates before the run,
                                       // then "t = T s (tick N): ..." for each mode found in it
  std::int64_t servo_ticks = 0, haptic_ticks = 0, physics_ticks = 0;
  double simulated = 0.0;   // s: how far the run got
  double wall = 0.0;        // s
  std::string error;        // non-empty when the run stopped early (Lua error, interrupt, ...)
  bool interrupted = false;
  // The run could not start (a device that cannot be opened): `error` says why, nothing was
  // written, and a file already at the output path is as it was.
  bool not_started = false;
  // The trace could not be written to its end or not be finished (a full disk): what failed and
  // what the file keeps (recordings::TraceWriter::close), and where it is.
  std::string trace_error;
  std::string pacing;        // with a pacer: its summary (overruns of how many ticks, worst lateness)
  std::int64_t overruns = 0; // with a pacer: servo ticks that missed their deadline
  // With a pacer and Lua trajectories: samples the loop held because the script thread's ring
  // for that trajectory ran dry (script_thread.hpp; also in `pacing`).
  std::int64_t script_holds = 0;
  bool passed() const;      // no error and every expectation met
};

// Runs the scenario to its end (or to an error), writing the trace. Throws OutputError when the
// output is an input, a directory, or taken by another run, and recordings::TraceError when the
// trace cannot be created: nothing is written then. A device that cannot be built ends the run
// before its first tick with nothing written (RunResult::not_started). Every later failure ends
// the run, closes the trace with status "error: ...", sets every device's force to zero, and is
// reported in RunResult; the trace is then renamed to the output path.
RunResult run_scenario(const scripting::Scenario& scenario, const RunOptions& options, const RunSeams& seams = {});

}  // namespace graspsim::app
