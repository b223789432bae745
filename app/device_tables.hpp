// /devices/<finger> (recordings/README.md "Schema"): every sample of a recorded finger's device as
// the device gave it, in its own frame, with the force sent to it in that frame, its own clock
// and sample numbers, and the tick's overrun flag. What a device has of these it says through
// the device interface (hw::Device: sample_time, sample_sequence, device_frame_sample, ...).
// The columns are recordings::DeviceRecorder's (its field tables in trace_schema.hpp); this
// class only gathers each row from the device.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "graspsim/engine/model.hpp"
#include "graspsim/hw/device.hpp"
#include "graspsim/recordings/device_recorder.hpp"
#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::app {

class DeviceTables {
 public:
  // One table for each finger f with record[f] (and a device), `block_rows` rows per block;
  // `counters`: with the `sequence` and `new_samples` columns; `every`: a row at every
  // every-th servo tick (n % every == 0; --record devices:EVERY).
  void open(recordings::TraceWriter& writer, const Model& model,
            const std::vector<std::unique_ptr<hw::Device>>& devices, const std::vector<bool>& record,
            std::size_t block_rows, bool counters, std::int64_t every = 1);
  // Servo tick n's row of every table (at a kept tick): `samples` as read (world), `rendered` (N, world), and
  // whether the tick overran its deadline (a replayed device records its own flag instead).
  void record(std::int64_t n, double t, const std::vector<hw::DeviceSample>& samples,
              const std::vector<hw::Vec3>& rendered, bool overrun);

 private:
  struct Table {
    std::size_t finger;   // Model::fingers index
    const hw::Device* device;
    recordings::DeviceRecorder recorder;
  };
  std::vector<Table> tables_;
  int rate_servo_ = 1;   // Hz
  std::int64_t every_ = 1;   // servo ticks between kept rows
};

}  // namespace graspsim::app
