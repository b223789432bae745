// Test helpers that edit a closed trace in place, through the schema-free HDF5 view
// (graspsim/recordings/h5_inspect.hpp), not the trace reader: read or rewrite one element of a
// column, or drop a column. A column "/physics/objects/box/position" is member
// "objects/box/position" of the compound table dataset "/physics" (schema 3); one row of it is
// read and written through a memory type that holds only that member, so nothing else changes.
#pragma once

#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "graspsim/recordings/h5_inspect.hpp"

namespace graspsim::test {

// Row `row` of column `path` of `file`: read into `values` (resized to the column's width), or
// with `write`, written from it.
inline void access_row(const std::string& file, const std::string& path, std::uint64_t row,
                       std::vector<double>& values, bool write) {
  using recordings::inspect::File;
  File f = File::open(file, write ? File::Mode::kReadWrite : File::Mode::kReadOnly);
  const std::size_t cut = path.find('/', 1);
  REQUIRE(cut != std::string::npos);
  const std::string table = path.substr(0, cut), member = path.substr(cut + 1);
  INFO("column " << path << " of " << file);
  if (write) f.write_member_row(table, member, row, values);   // throws unless values fill the width
  else values = f.read_member_row(table, member, row);
}

// Element (row, component) of column `path`.
inline double get_element(const std::string& file, const std::string& path, std::uint64_t row,
                          std::uint64_t component) {
  std::vector<double> values;
  access_row(file, path, row, values, false);
  REQUIRE(component < values.size());
  return values[component];
}

// Sets element (row, component) of column `path` to `value`.
inline void set_element(const std::string& file, const std::string& path, std::uint64_t row,
                        std::uint64_t component, double value) {
  std::vector<double> values;
  access_row(file, path, row, values, false);
  REQUIRE(component < values.size());
  values[component] = value;
  access_row(file, path, row, values, true);
}

// Adds `delta` to element (row, component) of column `path`; returns the new value.
inline double add_to_element(const std::string& file, const std::string& path, std::uint64_t row,
                             std::uint64_t component, double delta) {
  const double value = get_element(file, path, row, component) + delta;
  set_element(file, path, row, component, value);
  return value;
}

// Rewrites table `table` ("/physics") of `file` without column `member` (a trace one column
// short; the copy is contiguous and keeps no attributes).
inline void drop_column(const std::string& file, const std::string& table, const std::string& member) {
  using recordings::inspect::File;
  File::open(file, File::Mode::kReadWrite).drop_member(table, member);
}

}  // namespace graspsim::test
