// Repair of a trace cut by a crash (recordings/README.md, "Crash safety"): the one step after
// which h5dump and any HDF5 reader open it without SWMR.
#pragma once

#include <cstdint>
#include <string>

namespace graspsim::recordings {

struct RepairResult {
  bool repaired = false;      // false: the file was not cut (status not "running"), left alone
  std::string status_before;  // root "status" as found
  std::string status_after;   // "cut: repaired" when repaired, else status_before
  std::int64_t servo_rows = 0;   // rows of /servo/tick afterwards (-1 if there is no /servo)
};

// If the trace's root status is "running" (cut by a crash, or still being written: never repair
// a file a process is still writing), clears the superblock's SWMR/open status flags and moves
// the end-of-allocation past the end of the file (as `h5clear -s --increment` does, so nothing
// is truncated), writes status "cut: repaired", closes, and checks that the file now opens
// read-only without SWMR. A trace with any other status is not touched. Throws TraceError
// naming the file for a file that is not HDF5, not a graspsim trace (no root "status" or
// "schema_version"), or cannot be repaired.
RepairResult repair_trace(const std::string& path);

}  // namespace graspsim::recordings
