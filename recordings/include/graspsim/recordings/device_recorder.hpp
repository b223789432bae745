// DeviceRecorder: one /devices/<finger> row per servo tick for a finger driven by a device that
// is not scripted (the columns are the field tables kDeviceFields and kDeviceCounterFields of
// trace_schema.hpp, documented in recordings/README.md).
#pragma once

#include <cstddef>
#include <string>

#include "graspsim/recordings/trace_recorder.hpp"
#include "graspsim/recordings/trace_schema.hpp"
#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::recordings {

class DeviceRecorder {
 public:
  // The row it declares: kDeviceFields, and kDeviceCounterFields when `counters`.
  static RowSize row_size(bool counters);

  // Declares table /devices/<finger> in `writer` (which must outlive the recorder) and its
  // columns; `block_rows` as TraceWriter::table. The table's own attributes (the device, its
  // mapping, its force limit) are the runner's: table().set_attribute(".", ...). Throws
  // std::invalid_argument for a finger name that cannot be an HDF5 group name.
  DeviceRecorder(TraceWriter& writer, const std::string& finger, std::size_t block_rows, bool counters);

  TraceTable& table() { return table_; }

  // Appends one row; `counters` is written only if the table has those columns. Allocates
  // nothing after the table's first row.
  void record(const schema::DeviceRow& row, const schema::DeviceCounterRow& counters = {});

 private:
  TraceTable& table_;
  std::size_t row_ = 0;        // offset of the first kDeviceFields column
  std::size_t counters_ = 0;   // offset of the first kDeviceCounterFields column
  bool has_counters_ = false;
};

}  // namespace graspsim::recordings
