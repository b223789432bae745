// /devices/<finger>: every device sample in the device's own terms (device_tables.hpp).
#include "app/device_tables.hpp"

#include <cstdio>

namespace graspsim::app {

void DeviceTables::open(recordings::TraceWriter& writer, const Model& model,
                        const std::vector<std::unique_ptr<hw::Device>>& devices, const std::vector<bool>& record,
                        std::size_t block_rows, bool counters, std::int64_t every) {
  rate_servo_ = model.rates.servo;
  every_ = every;
  for (std::size_t f = 0; f < record.size() && f < devices.size(); ++f) {
    if (!record[f]) continue;
    const hw::Device& device = *devices[f];
    // Gaps and holds at the device's own rate (Device::sample_sequence; -1 for a device without)
    // are the counter columns, written when `counters`.
    Table& c = tables_.emplace_back(Table{f, &device, {writer, model.fingers[f].name, block_rows, counters}});
    recordings::TraceTable& t = c.recorder.table();
    t.set_attribute(".", "device", device.describe());
    t.set_attribute(".", "mapping", device.mapping_text());
    char limit[32];
    std::snprintf(limit, sizeof limit, "%.17g", device.limits().max_force);
    t.set_attribute(".", "max_force", limit);   // N: the clamp the run used (a replay uses it again)
  }
}

void DeviceTables::record(std::int64_t n, double t, const std::vector<hw::DeviceSample>& samples,
                          const std::vector<hw::Vec3>& rendered, bool overrun) {
  if (tables_.empty() || n % every_ != 0) return;
  for (Table& c : tables_) {
    const hw::Device& d = *c.device;
    // The device's own view: before any mapping (device frame), and the force it was sent.
    const hw::DeviceSample* frame = d.device_frame_sample();
    const hw::DeviceSample& raw = frame ? *frame : samples[c.finger];
    const hw::Vec3* frame_force = d.device_frame_force();
    recordings::schema::DeviceRow row;
    row.tick = n;
    row.time = static_cast<double>(n) / rate_servo_;
    row.device_time = d.has_sample_clock() ? d.sample_time() : t;
    row.position = raw.position;
    row.gimbal = raw.gimbal;
    row.buttons = static_cast<std::int64_t>(raw.buttons);
    row.force = frame_force ? *frame_force : rendered[c.finger];
    row.overrun = (d.has_recorded_pacing() ? d.recorded_overrun() : overrun) ? 1 : 0;
    c.recorder.record(row, {d.sample_sequence(), d.new_samples()});
  }
}

}  // namespace graspsim::app
