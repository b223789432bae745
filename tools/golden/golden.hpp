// Golden traces (README.md, "Golden traces"): one small trace per scenario under
// tests/golden/, written by `tools/bless` and checked by tests/golden/test_golden.cpp. Both go
// through the same three steps: run the scenario at its own rates (a full trace), decimate it
// into a golden-sized copy, compare with recordings::compare_traces, bitwise.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "app/run.hpp"
#include "graspsim/recordings/trace_compare.hpp"

namespace graspsim::golden {

// The golden of `scenario_file` (scenarios/X.lua -> <golden_dir>/X.h5).
std::string golden_path(const std::string& golden_dir, const std::string& scenario_file);

// The command that re-blesses it, for messages: "tools/bless scenarios/X.lua".
std::string bless_command(const std::string& scenario_file);

// Runs the scenario as the golden test and `tools/bless` do: loaded with no override, at its
// own rates and duration, full trace (every row, uncompressed) to `trace`.
app::RunResult run_for_golden(const std::string& scenario_file, const std::string& trace);

// How a full trace becomes a golden: the rows of every table whose tick is a multiple of `stride`
// servo ticks; 0 means rate_servo / min(rate_physics, kGoldenRowsPerSecond), i.e. every /physics
// row (with the state hash of the whole State) and the /servo and /haptic rows at physics ticks, up
// to 500 physics rows per simulated second (a 3 kHz physics loop keeps every 6th: every row of a
// 2 s stack at 3 kHz would make a 2.1 MB golden; any divergence persists to a kept tick). Shuffle +
// deflate at `compression` (1..9). Root and dataset attributes are copied; the root gets `golden`
// (what was kept) and `golden_cpu` (the CPU model it was blessed on).
inline constexpr std::int64_t kGoldenRowsPerSecond = 500;   // most physics rows kept per s

struct DecimateOptions {
  std::int64_t stride = 0;   // servo ticks
  int compression = 9;
  std::string blessed_changes;   // root attribute `blessed_changes` when not empty: what the bless
                                 //    that wrote this golden changed against the one before
};

// Writes the decimated copy of trace `in` to `out` (replacing it), through
// recordings::decimate_trace with the stride above and the golden's root attributes. Throws
// recordings::TraceError naming the file and dataset on failure.
void decimate_trace(const std::string& in, const std::string& out, const DecimateOptions& options = {});

// The fresh run's trace compared with its golden, bitwise, and what to say about it.
struct GoldenCheck {
  recordings::CompareResult result;
  bool same = false;       // bit-identical on every golden row, and every golden row matched
  std::string message;     // why not (first divergence, what to run); empty when same
};

// Compares a fresh full trace `fresh` with `golden` (bitwise; each golden row must find its
// tick in the fresh trace). Throws recordings::CompareInputError for unusable files.
GoldenCheck check_against_golden(const std::string& fresh, const std::string& golden,
                                 const std::string& scenario_file);

// "first divergence at tick T (t = S s): physics/objects/box/position z: golden A, run B" and
// up to `max_datasets` lines "path: max abs error E, max rel error R, N of M elements".
// Then per loop the ticks in one trace only; `only_b` alone: rows only in B (a decimated golden
// leaves most run rows unmatched, which is not news).
std::string divergence_summary(const recordings::CompareResult& result, std::size_t max_datasets = 12,
                               bool only_b = false);

// The CPU model ("model name" of /proc/cpuinfo), "unknown" if not found.
std::string cpu_model();

}  // namespace graspsim::golden
