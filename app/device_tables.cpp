// /devices/<finger>: every device sample in the device's own terms (device_tables.hpp).
#include "app/device_tables.hpp"

#include <cstdio>

namespace graspsim::app {

void DeviceTables::open(recordings::TraceWriter& writer, const Model& model,
                        const std::vector<std::unique_ptr<hw::Device>>& devices, const std::vector<bool>& record,
                        std::size_t block_rows, bool counters) {
  using recordings::DType;
  rate_servo_ = model.rates.servo;
  for (std::size_t f = 0; f < record.size() && f < devices.size(); ++f) {
    if (!record[f]) continue;
    const hw::Device& device = *devices[f];
    Table c{f, &device, &writer.table("devices/" + model.fingers[f].name, block_rows), 0, 0, 0, 0, 0, 0, 0, 0};
    recordings::TraceTable& t = *c.table;
    c.tick = t.add_column("tick", 1, DType::kInt64, "tick");
    c.time = t.add_column("time", 1, DType::kFloat64, "s");
    c.device_time = t.add_column("device_time", 1, DType::kFloat64, "s");
    c.position = t.add_column("position", 3, DType::kFloat64, "m");
    c.gimbal = t.add_column("gimbal", 3, DType::kFloat64, "rad");
    c.buttons = t.add_column("buttons", 1, DType::kInt64, "1");
    c.force = t.add_column("force", 3, DType::kFloat64, "N");
    c.overrun = t.add_column("overrun", 1, DType::kInt8, "1");
    // Gaps and holds at the device's own rate (Device::sample_sequence; -1 for a device without).
    if (counters) {
      c.sequence = t.add_column("sequence", 1, DType::kInt64, "1");
      c.new_samples = t.add_column("new_samples", 1, DType::kInt64, "1");
    }
    t.set_attribute(".", "device", device.describe());
    t.set_attribute(".", "mapping", device.mapping_text());
    t.set_attribute("gimbal", "order", "roll, pitch, yaw");
    char limit[32];
    std::snprintf(limit, sizeof limit, "%.17g", device.limits().max_force);
    t.set_attribute(".", "max_force", limit);   // N: the clamp the run used (a replay uses it again)
    tables_.push_back(c);
  }
}

void DeviceTables::record(std::int64_t n, double t, const std::vector<hw::DeviceSample>& samples,
                          const std::vector<hw::Vec3>& rendered, bool overrun) {
  for (const Table& c : tables_) {
    const hw::Device& d = *c.device;
    // The device's own view: before any mapping (device frame), and the force it was sent.
    const hw::DeviceSample* frame = d.device_frame_sample();
    const hw::DeviceSample& raw = frame ? *frame : samples[c.finger];
    const hw::Vec3* frame_force = d.device_frame_force();
    const hw::Vec3& force = frame_force ? *frame_force : rendered[c.finger];
    double* row = c.table->append_row();
    row[c.tick] = static_cast<double>(n);
    row[c.time] = static_cast<double>(n) / rate_servo_;
    row[c.device_time] = d.has_sample_clock() ? d.sample_time() : t;
    for (int i = 0; i < 3; ++i) {
      row[c.position + i] = raw.position[i];
      row[c.gimbal + i] = raw.gimbal[i];
      row[c.force + i] = force[i];
    }
    row[c.buttons] = static_cast<double>(raw.buttons);
    row[c.overrun] = (d.has_recorded_pacing() ? d.recorded_overrun() : overrun) ? 1.0 : 0.0;
    if (c.sequence != kNoColumn) {
      row[c.sequence] = static_cast<double>(d.sample_sequence());
      row[c.new_samples] = static_cast<double>(d.new_samples());
    }
  }
}

}  // namespace graspsim::app
