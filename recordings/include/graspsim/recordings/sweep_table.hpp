// A sweep's summary table as HDF5 (`graspsim sweep`, README.md "Sweeps"): one dataset `/runs` of
// compound rows, one member per column, in the columns' order, so that h5py's
// f["runs"]["mu"] is one column as a numpy array. Lives here because only recordings/ includes HDF5.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace graspsim::recordings {

struct SweepColumn {
  enum class Kind { text, integer, real };
  std::string name;                  // the member's name, as in the CSV's header
  std::string unit;                  // written to the attribute `units`; "" for none
  Kind kind = Kind::text;
  std::vector<std::string> text;     // kind text: one per row (UTF-8, variable length)
  std::vector<std::int64_t> integers;   // kind integer: int64
  std::vector<double> reals;         // kind real: IEEE double
  std::size_t rows() const;
};

// Writes `columns` (all with the same number of rows; names unique and non-empty) as the
// dataset /runs of a new HDF5 file at `path`, with `attributes` as scalar string root
// attributes and the root attribute `units` ("name=unit" lines, one per column with a unit).
// The file is written as "<path>.partial" and renamed to `path` at the end, so a file already at
// `path` is replaced only by a complete table. Throws TraceError naming the path on failure.
void write_sweep_table(const std::string& path, const std::vector<SweepColumn>& columns,
                       const std::vector<std::pair<std::string, std::string>>& attributes);

}  // namespace graspsim::recordings
