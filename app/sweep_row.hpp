// One finished run of a sweep: its grid point, seed, exit status, wall time and expectations,
// kept as DIR/runs/<index>.row (written whole, by rename), so that a resumed sweep keeps it and
// a Slurm array task hands it to the collecting sweep.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "app/sweep_plan.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::app::sweep {

struct Expectation {
  std::string what;
  bool passed = false;
  std::string measured;   // the text the scenario's check returned ("rose 80.0 mm")
};

struct Row {
  std::size_t index = 0;
  std::vector<std::string> values;     // one per grid axis
  std::optional<std::uint64_t> seed;
  int exit_status = 0;                 // of `graspsim run`: 0 pass, 1 fail, 2 bad input, 3 trace, 128 + signal
  double wall = 0.0;                   // s: the run's process, start to end
  std::string trace;                   // the trace's path relative to the sweep's folder; "" none
  std::string error;                   // exit >= 2: graspsim's last error line (without "graspsim: ")
  std::vector<Expectation> expectations;   // in the scenario's order; empty if the run never got there
};

// The `--summary FILE` of `graspsim run`: one line per expectation, "PASS|FAIL\twhat\tmeasured".
std::string summary_text(const std::vector<scripting::ExpectationResult>& expectations);
std::vector<Expectation> parse_summary(const std::string& text);

// Writes `text` to `path` whole: into "<path>.partial", created new (O_EXCL: a file of that name
// already there is never truncated nor removed), then renamed over `path`. Returns "" or why not
// (the file and strerror); on failure the partial it created is removed.
std::string write_summary(const std::string& path, const std::string& text);

std::string row_text(const Row& row);
Row parse_row(const std::string& text, const std::string& file);   // throws SweepError

// Writes the row of `plan`'s run to its file (a .partial renamed into place); throws SweepError.
void write_row(const Plan& plan, const std::string& dir, const Row& row);
// The run's row, if its file exists and belongs to this plan's run (same index, values and seed).
std::optional<Row> read_row(const Plan& plan, const std::string& dir, std::size_t index);

std::string read_file(const std::string& path);   // "" when it cannot be read or is no regular file

// Throws SweepError when something other than a regular file is at `path` (a directory, a
// device, a FIFO, a socket: output_file.hpp, not_replaceable): a sweep replaces only files.
void check_replaceable(const std::string& path);

}  // namespace graspsim::app::sweep
