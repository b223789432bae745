// The trace of one run: its output path claimed, the writer, the root attributes that make the
// file explain and replay itself, the rows of every loop, the flush schedule that bounds what a
// crash loses, and how the file is finished and takes its name (output_file.hpp).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "app/output_file.hpp"
#include "app/run.hpp"
#include "graspsim/recordings/trace_recorder.hpp"
#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::app {

using RunClock = std::chrono::steady_clock;

// The files a run of `scenario` reads, none of which it may write: `options.inputs` (the devices'
// files), the scenario and its mesh files.
std::vector<InputFile> run_inputs(const scripting::Scenario& scenario, const RunOptions& options);

// Crash safety (recordings/README.md): a run killed at any moment loses less than kFlushSimulated
// of simulated time, however far the writer thread lags. The trace is flushed every flush
// interval (at most kFlushSimulated / (kFlushesInFlight + 1) of simulated time), and before a
// flush is handed to the writer the one kFlushesInFlight flushes before it must be on disk: the
// loop waits for it if need be (a slow disk slows the run rather than break the bound). So the
// file always holds every tick up to kFlushesInFlight + 1 intervals ago. One in flight: two
// cost the 40 s lift 12 ms more process CPU than none (three times the flushes), one 6 ms
// (recordings/README.md "Crash safety"). It is also flushed at least every kFlushWall seconds of
// wall time (a run slower than real time). The wall clock is read every kWallCheckTicks ticks;
// it decides only when rows reach the disk, never what is written.
inline constexpr double kFlushSimulated = 0.25;   // s, simulated
inline constexpr int kFlushesInFlight = 1;
inline constexpr double kFlushWall = 0.9;         // s, wall (under 1 s, with the check interval's slack)
inline constexpr std::int64_t kWallCheckTicks = 64;

class RunTrace {
 public:
  // Claims options.out (or the scenario's default name), opens the trace under its partial name
  // and writes the root attributes. Throws OutputError when the output is an input, a directory,
  // or taken by another run, and recordings::TraceError when the trace cannot be created:
  // nothing is written then. Without options.trace.write there is no file, and every call below
  // does nothing.
  RunTrace(const scripting::Scenario& scenario, const RunOptions& options);
  // Not finished (an exception escaped before the first tick: a full disk): the trace is closed
  // and removed, and the output path is as it was.
  ~RunTrace();
  RunTrace(const RunTrace&) = delete;
  RunTrace& operator=(const RunTrace&) = delete;

  const std::string& path() const { return path_; }   // where the trace goes; "" without one
  recordings::TraceWriter* writer() { return writer_ ? &*writer_ : nullptr; }
  template <typename T>
  void set_attribute(const std::string& name, const T& value) {
    if (writer_) writer_->set_attribute(name, value);
  }

  // Declares /servo, /haptic and /physics; `start` begins the wall-clock flush interval.
  void open_tables(const Model& model, std::size_t block_rows, RunClock::time_point start);
  // Rows per table block: options' block_rows, else one flush interval.
  std::size_t block_rows() const { return block_rows_ > 0 ? block_rows_ : static_cast<std::size_t>(flush_ticks_); }
  // One row per loop that ran at this tick.
  void record(const TickRecord& record, const std::vector<Vec3>& rendered, const Input& input, const State& state) {
    if (recorder_) recorder_->record(record, rendered, input, state);
  }
  // After servo tick n's rows: hands a flush to the writer when one is due (kFlushSimulated).
  void flush_if_due(std::int64_t n);

  // Closes the trace with the run's status ("complete" or "error: ...") and its expectations
  // and warnings, and gives it the output path (a run that never started leaves nothing).
  // Fills result.trace_path and result.trace_error.
  void finish(RunResult& result, bool started, const std::string& warnings);

 private:
  void abandon();

  std::string path_;
  recordings::RecordSelection record_;   // the loops written, and how often (RunOptions::Trace::record)
  std::optional<OutputClaim> claim_;   // the output path, locked; the trace is written to its partial name
  std::optional<recordings::TraceWriter> writer_;
  std::optional<recordings::TraceRecorder> recorder_;
  bool finished_ = false;
  std::size_t block_rows_ = 0;
  // The flush schedule (kFlushSimulated).
  std::int64_t flush_ticks_ = 1;     // servo ticks between flushes on simulated time
  std::int64_t until_flush_ = 1;     // servo ticks to the next one
  std::array<std::uint64_t, kFlushesInFlight> tickets_{};   // the last kFlushesInFlight flushes handed over
  std::size_t oldest_ = 0;           // the oldest of them
  RunClock::time_point last_flush_;
};

}  // namespace graspsim::app
