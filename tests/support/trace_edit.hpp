// Test helpers that edit a closed trace in place, through the schema-free HDF5 view
// (graspsim/recordings/h5_inspect.hpp), not the trace reader: read or rewrite one element of a
// column, or drop a column. A column "/physics/objects/box/position" is member
// "objects/box/position" of the compound table dataset "/physics" (schema 3), or field "position"
// of element k of member "objects", an array of one compound per object, k being the line of the
// table's attribute "objects" that says "box" (schema 4). One row of it is read and written
// through a memory type that holds only that member, so nothing else changes.
#pragma once

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "graspsim/recordings/h5_inspect.hpp"

namespace graspsim::test {

// Where column `member` ("objects/box/position") of `table` is stored in a schema 4 trace: the
// group member ("objects"), the entity's index in it and the field ("position"); index -1 when
// the column is a member of its own.
struct EntityField {
  std::string group;
  std::int64_t index = -1;
  std::string field;
};
inline EntityField entity_field(const recordings::inspect::File& f, const std::string& table, const std::string& member) {
  const recordings::inspect::DatasetInfo info = f.dataset(table);
  const std::size_t first = member.find('/'), second = member.find('/', first + 1);
  if (first == std::string::npos || second == std::string::npos) return {};
  const std::string group = member.substr(0, first);
  const bool grouped = std::any_of(info.members.begin(), info.members.end(),
                                   [&](const auto& m) { return m.name == group && !m.fields.empty(); });
  if (!grouped) return {};
  std::istringstream names(f.read_string_attribute(table, group));
  std::int64_t k = 0;
  for (std::string line; std::getline(names, line); ++k)
    if (line == member.substr(first + 1, second - first - 1)) return {group, k, member.substr(second + 1)};
  return {};
}

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
  const EntityField e = entity_field(f, table, member);
  const auto index = static_cast<std::uint64_t>(e.index);
  if (e.index >= 0 && write) f.write_element_row(table, e.group, index, e.field, row, values);
  else if (e.index >= 0) values = f.read_element_row(table, e.group, index, e.field, row);
  else if (write) f.write_member_row(table, member, row, values);   // throws unless values fill the width
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
// short; the copy is contiguous and keeps the table's attributes). In a schema 4 trace a column of an
// entity goes with the same field of every entity of its group ("objects/box/torque": every
// object's torque).
inline void drop_column(const std::string& file, const std::string& table, const std::string& member) {
  using recordings::inspect::File;
  File f = File::open(file, File::Mode::kReadWrite);
  const EntityField e = entity_field(f, table, member);
  f.drop_member(table, e.index >= 0 ? e.group + "/" + e.field : member);
}

}  // namespace graspsim::test
