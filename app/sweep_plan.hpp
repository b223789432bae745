// A sweep (`graspsim sweep`, README.md "Sweeps"): the cross product of --set values, times seeds
// of jittered waypoints, each one run of `graspsim run` in its own process. The plan says which
// runs there are, in which order, and with which arguments; it is written to DIR/sweep.plan so
// that a resumed sweep and every Slurm array task read the same one.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace graspsim::app::sweep {

// Bad sweep input (a grid, a plan file): the message names the flag or file.
class SweepError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One grid axis: a scenario field (or param()) and the values it takes, as --set would get them.
struct Axis {
  std::string name;
  std::vector<std::string> values;
};

// "NAME=V1,V2,..." (or "NAME=V1;V2;..." when a value holds commas, as gravity=0,0,-1.62 does).
// Throws SweepError naming the --grid for an empty name or value, or a value given twice.
Axis parse_axis(const std::string& grid);

struct Plan {
  std::string scenario;              // absolute path, so a Slurm task started anywhere finds it
  std::vector<Axis> grid;            // the first axis changes slowest
  std::vector<std::string> sets;     // --set NAME=VALUE given to every run
  std::uint64_t seeds = 0;           // 0: no jitter; N: --jitter-seed 0 .. N-1 for every grid point
  double jitter = 0.5e-3;            // m: --jitter amplitude of a seeded run
  bool keep_traces = false;          // each run writes runs/<index>.h5; else --no-trace

  struct Run {
    std::size_t index = 0;
    std::vector<std::string> values;   // one per axis
    std::optional<std::uint64_t> seed;
  };
  std::size_t size() const;          // grid points x max(seeds, 1)
  Run run(std::size_t index) const;  // seed changes fastest, then the last axis, ...
  // The arguments of `graspsim` for run `index` whose files go to `dir`:
  // run SCENARIO --set ... [--jitter A --jitter-seed S] (--out F.h5 | --no-trace) --quiet --summary F
  std::vector<std::string> run_arguments(std::size_t index, const std::string& dir) const;
  // Files of run `index` in the sweep's folder `dir`: runs/<index, zero-padded>.<extension>.
  std::string run_file(const std::string& dir, std::size_t index, const std::string& extension) const;

  std::string text() const;                  // the plan file's contents (tab-separated lines)
  static Plan parse(const std::string& text, const std::string& file);   // throws SweepError
};

// Tab, newline, carriage return and backslash as \t \n \r \\, so a field fits one line.
std::string escape(const std::string& field);
std::string unescape(const std::string& field);
// Splits at tabs (fields escaped).
std::vector<std::string> split_tabs(const std::string& line);

}  // namespace graspsim::app::sweep
