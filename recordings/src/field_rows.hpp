// Field tables (trace_schema.hpp) put to work on a TraceTable: declare a record's columns,
// fill them from a record, count a record's row size. Shared by TraceRecorder and
// DeviceRecorder.
#pragma once

#include <cstddef>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "graspsim/recordings/trace_recorder.hpp"
#include "graspsim/recordings/trace_schema.hpp"
#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::recordings::schema {

// Declares `fields` in `table` under `prefix`, in table order, with their units and notes;
// returns the offset of the first (the others follow it: add_column packs columns in order).
template <typename Record, std::size_t N>
std::size_t declare(TraceTable& table, const std::string& prefix, const Field<Record> (&fields)[N]) {
  std::size_t first = 0;
  for (std::size_t k = 0; k < N; ++k) {
    const Field<Record>& f = fields[k];
    const std::string path = prefix + std::string(f.name);
    const std::size_t offset = table.add_column(path, f.width, f.dtype, std::string(f.units));
    if (k == 0) first = offset;
    if (!f.note.name.empty()) table.set_attribute(path, std::string(f.note.name), std::string(f.note.value));
  }
  return first;
}

// Declares `fields` for every one of `entities` as group `group` of `table` (TraceTable::add_group),
// with their units and notes (one per field, shared by the entities); returns the offset of the
// first entity's first field. Entity k's fields start `size_of_fields(fields).values` * k after it.
template <typename Record, std::size_t N>
std::size_t declare_group(TraceTable& table, const std::string& group, const std::vector<std::string>& entities,
                          const Field<Record> (&fields)[N]) {
  std::vector<TraceTable::Field> spec;
  for (const Field<Record>& f : fields) spec.push_back({std::string(f.name), f.width, f.dtype, std::string(f.units)});
  const std::size_t first = table.add_group(group, entities, spec);
  for (const Field<Record>& f : fields)
    if (!f.note.name.empty())
      table.set_attribute(group + "/" + std::string(f.name), std::string(f.note.name), std::string(f.note.value));
  return first;
}

// Writes every field of `record` into `row` from `offset` on, in table order. The table is a
// template argument so that each field's put is a constant, called directly and inlined: the
// recorder then costs what hand-written stores into the row cost (tools/bench/trace_overhead.cpp,
// 40 s lift: the run loop's CPU time with the trace on is 33 to 35 ms either way; called through
// the pointers in a loop over the table, 37 to 41 ms).
template <const auto& Fields, std::size_t I, typename Record>
void put_field(const Record& record, double*& out) {
  constexpr auto put = Fields[I].put;
  constexpr int width = Fields[I].width;
  put(record, out);
  out += width;
}

template <const auto& Fields, typename Record>
void fill(double* row, std::size_t offset, const Record& record) {
  double* out = row + offset;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (put_field<Fields, I>(record, out), ...);
  }(std::make_index_sequence<std::size(Fields)>{});
}

// Doubles and stored bytes of one copy of `fields`.
template <typename Record, std::size_t N>
RowSize size_of_fields(const Field<Record> (&fields)[N]) {
  RowSize size;
  for (const Field<Record>& f : fields) {
    size.values += static_cast<std::size_t>(f.width);
    size.bytes += static_cast<std::size_t>(f.width) * size_of(f.dtype);
  }
  return size;
}

}  // namespace graspsim::recordings::schema

namespace graspsim::recordings {

inline RowSize operator+(RowSize a, RowSize b) { return {a.values + b.values, a.bytes + b.bytes}; }
inline RowSize operator*(std::size_t n, RowSize a) { return {n * a.values, n * a.bytes}; }

}  // namespace graspsim::recordings
