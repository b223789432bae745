// How a command that writes a trace is stopped: SIGINT, SIGTERM and SIGHUP end a run or a replay
// at its next check, its trace closed and marked (exit 128 + the signal).
#pragma once

#include <atomic>

namespace graspsim::cli {

struct StopFlags {
  std::atomic<bool> interrupt{false};   // set by a stop signal
  std::atomic<int> signal{0};           // which one
};

// The process's flags, set by the handlers handle_stop_signals() installs.
StopFlags& stop_flags();

// Installs the handlers of SIGINT, SIGTERM and SIGHUP, and ignores SIGXFSZ (a file-size limit,
// `ulimit -f`), so that a write past it fails with EFBIG and ends the run like a full disk
// instead of killing it.
void handle_stop_signals();

}  // namespace graspsim::cli
