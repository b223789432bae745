// Small helpers that read a trace back, one call per dataset or attribute (for tests and
// tools; each call opens and closes the file).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::recordings {

struct Dataset {
  std::vector<double> values;       // row-major, converted to double (integers exact to 2^53;
                                    //   uint64 rounded to the nearest double)
  std::vector<std::uint64_t> bits;  // uint64 datasets only (a hash): the exact values, row-major
  std::vector<std::size_t> shape;   // (n,) or (n, width)
  std::string units;                // the "units" attribute, "" if there is none
  DType dtype = DType::kFloat64;    // on-disk type
};

// Reads a whole dataset ("/servo/time"), or one column of a table ("/physics/objects/box/position";
// a table is read whole to give one of its columns: read_table reads many in one pass). A trace still being written or cut by a crash (marked
// for SWMR writing) is opened as a SWMR reader. Throws TraceError naming the file and the path if the
// file is not an HDF5 file, the path is missing or not a dataset, or its type is not one of DType.
Dataset read_dataset(const std::string& file, const std::string& path);
// Columns of one table, read in one pass over its rows.
struct Table {
  std::vector<std::string> names;   // relative to the table ("tick", "objects/box/position")
  std::vector<Dataset> columns;     // names[k]'s, as read_dataset gives it
  std::vector<std::size_t> sorted;  // indices of `names` in name order (read_table fills it)
  // The column `name`; throws TraceError if it was not read.
  const Dataset& column(const std::string& name) const;
};
// Columns `names` of table `table` ("/physics", "/devices/thumb", or a schema 2 group of
// datasets), each as read_dataset(file, table + "/" + name) gives it; `names` empty: every column,
// sorted. Whatever the layout, the rows are read once (a 1000-object /physics is 11000 columns).
// Throws TraceError as read_dataset does, for a table that is not there, or a name that is not
// one of its columns.
Table read_table(const std::string& file, const std::string& table, const std::vector<std::string>& names = {});
// Every dataset list_datasets names, in its order, each table read once: what read_dataset gives
// for each path.
std::vector<std::pair<std::string, Dataset>> read_trace(const std::string& file);
// Every path read_dataset reads in the file, sorted: each column of each table ("/physics/tick",
// "/physics/objects/box/position", "/devices/thumb/force", ...) and each plain dataset. Throws
// TraceError if the file cannot be opened as HDF5.
std::vector<std::string> list_datasets(const std::string& file);
// Attribute `name` of the group or dataset `object_path` ("/" for the root).
std::string read_string_attribute(const std::string& file, const std::string& object_path,
                                  const std::string& name);
std::int64_t read_int_attribute(const std::string& file, const std::string& object_path,
                                const std::string& name);
double read_double_attribute(const std::string& file, const std::string& object_path,
                             const std::string& name);   // float or integer attribute
bool has_attribute(const std::string& file, const std::string& object_path,
                   const std::string& name);
// Whether a group or dataset exists at `path` (false for a missing intermediate group too).
// Throws TraceError if the file cannot be opened as HDF5.
bool has_object(const std::string& file, const std::string& path);

}  // namespace graspsim::recordings
