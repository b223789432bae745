// DeviceRecorder: the /devices/<finger> table from its field tables.
#include "graspsim/recordings/device_recorder.hpp"

#include <stdexcept>

#include "field_rows.hpp"

namespace graspsim::recordings {

RowSize DeviceRecorder::row_size(bool counters) {
  const RowSize row = schema::size_of_fields(schema::kDeviceFields);
  return counters ? row + schema::size_of_fields(schema::kDeviceCounterFields) : row;
}

namespace {
TraceTable& device_table(TraceWriter& writer, const std::string& finger, std::size_t block_rows) {
  if (finger.empty() || finger == "." || finger == ".." || finger.find('/') != std::string::npos) {
    throw std::invalid_argument("trace: finger name '" + finger +
                                "' cannot be an HDF5 group name (empty, '.', '..' or has '/')");
  }
  return writer.table(std::string(schema::kDevices) + finger, block_rows);
}
}  // namespace

DeviceRecorder::DeviceRecorder(TraceWriter& writer, const std::string& finger, std::size_t block_rows,
                               bool counters)
    : table_(device_table(writer, finger, block_rows)), has_counters_(counters) {
  row_ = schema::declare(table_, "", schema::kDeviceFields);
  if (counters) counters_ = schema::declare(table_, "", schema::kDeviceCounterFields);
}

void DeviceRecorder::record(const schema::DeviceRow& row, const schema::DeviceCounterRow& counters) {
  double* out = table_.append_row();
  schema::fill<schema::kDeviceFields>(out, row_, row);
  if (has_counters_) schema::fill<schema::kDeviceCounterFields>(out, counters_, counters);
}

}  // namespace graspsim::recordings
