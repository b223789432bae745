// What a run will need, worked out before it starts (README.md, "Run length and rates"): the
// memory its trace writer holds at once and the disk its trace takes, from the model, the run's
// length and its devices. A run that will not fit on this machine is refused before anything is
// written, naming the figure, instead of ending in a bare std::bad_alloc or a full disk. (The
// ceilings on duration and rates themselves are the scenario loader's: scripting/README.md.)
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "app/run.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::app {

// One table of the trace, as the estimate counts it.
struct TableFootprint {
  std::string name;              // "/servo", "/haptic", "/physics", "/devices/<finger>"
  std::size_t values = 0;        // doubles per row in the writer's blocks
  std::size_t bytes = 0;         // bytes per stored row
  double block_rows = 0.0;       // rows per writer block (and chunk)
  double rows = 0.0;             // rows in the run
};

struct RunFootprint {
  std::vector<TableFootprint> tables;
  std::int64_t servo_ticks = 0;   // ticks the run will take
  double memory = 0.0;            // bytes: every table's writer blocks and packing buffer at once
  double disk = 0.0;              // bytes: the trace's rows, uncompressed (attributes not counted)
  std::string memory_detail;      // which table needs most, and why ("/servo: 4 blocks of ...")
};

// For `scenario` run with `options` (its max_ticks, block_rows, background_writer and the
// fingers whose devices get a /devices table). Each table's block is one flush interval of its
// loop (flush_interval_ticks), held 4 times with the background writer (1 without) as doubles,
// plus one packed block; every row goes to the file at its stored size.
RunFootprint estimate_footprint(const scripting::Scenario& scenario, const RunOptions& options);

// What this machine has for it, in bytes (negative: unknown, not checked).
struct MachineRoom {
  double memory_available = -1.0;   // /proc/meminfo MemAvailable
  double disk_free = -1.0;          // free to this user in the output's directory (statvfs)
};
MachineRoom machine_room(const std::string& out_path);

// "" when the run fits; otherwise why not, with both figures. A table whose chunk (its block,
// one flush interval of rows) would pass HDF5's chunk limit (recordings::kMaxChunkBytes, 4 GiB) is
// refused on any machine. A compressed trace (compression >
// 0) is not refused for disk: its size is not known before (deflate gives 5 to 10x on traces,
// recordings/README.md); `warning` then says how much it would need uncompressed.
std::string refusal(const RunFootprint& need, const MachineRoom& room, int compression, std::string* warning);

// The three together, for the CLI: "" or the refusal; `warning` as refusal's. `out_path` as
// RunOptions::out ("" = the scenario's default name in the working directory).
std::string check_run_fits(const scripting::Scenario& scenario, const RunOptions& options, std::string* warning);

}  // namespace graspsim::app
