// Tests of DeviceRecorder: a device's samples land in /devices/<finger> with the documented
// columns, exact values, and the row size row_size() gives.
#include <catch2/catch.hpp>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspsim/recordings/device_recorder.hpp"
#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "tests/support/library.hpp"

using namespace graspsim;
using namespace graspsim::recordings;

namespace {

std::string tmp_path(const std::string& name) { return graspsim::test::fresh_tmp_path("recordings_", name); }

// A distinct value for every (tick, field, component), with no short binary form.
double v(std::int64_t tick, int field, int component) {
  return static_cast<double>(tick) / 7.0 + field * 10.0 + component / 3.0;
}

schema::DeviceRow row_at(std::int64_t tick) {
  schema::DeviceRow r;
  r.tick = tick;
  r.time = static_cast<double>(tick) / 1000.0;
  r.device_time = v(tick, 1, 0);
  r.position = Vec3(v(tick, 2, 0), v(tick, 2, 1), v(tick, 2, 2));
  r.gimbal = Vec3(v(tick, 3, 0), v(tick, 3, 1), v(tick, 3, 2));
  r.buttons = tick % 4;
  r.force = Vec3(v(tick, 4, 0), v(tick, 4, 1), v(tick, 4, 2));
  r.overrun = static_cast<std::int8_t>(tick % 2);
  return r;
}

}  // namespace

TEST_CASE("a device's rows land in /devices/<finger> exactly, with or without the counters",
          "[device_recorder]") {
  for (const bool counters : {false, true}) {
    INFO("counters " << counters);
    const std::string file = tmp_path(counters ? "device_counters.h5" : "device.h5");
    const std::int64_t ticks = 37;   // more than one block of 16 rows, and a partial one
    {
      TraceWriter writer(file);
      DeviceRecorder recorder(writer, "index", 16, counters);
      recorder.table().set_attribute(".", "device", "test device");
      for (std::int64_t tick = 0; tick < ticks; ++tick)
        recorder.record(row_at(tick), schema::DeviceCounterRow{3 * tick, tick % 3});
      writer.close("complete");
    }
    const auto position = read_dataset(file, "/devices/index/position");
    const auto buttons = read_dataset(file, "/devices/index/buttons");
    const auto overrun = read_dataset(file, "/devices/index/overrun");
    REQUIRE(position.shape == std::vector<std::size_t>{static_cast<std::size_t>(ticks), 3});
    CHECK(position.units == "m");
    CHECK(buttons.dtype == DType::kInt64);
    CHECK(overrun.dtype == DType::kInt8);
    for (std::int64_t t = 0; t < ticks; ++t) {
      const schema::DeviceRow r = row_at(t);
      const auto k = static_cast<std::size_t>(t);
      for (int i = 0; i < 3; ++i) CHECK(position.values[3 * k + static_cast<std::size_t>(i)] == r.position[i]);
      CHECK(buttons.values[k] == static_cast<double>(r.buttons));
      CHECK(overrun.values[k] == static_cast<double>(r.overrun));
    }
    CHECK(read_string_attribute(file, "/devices/index", "gimbal/order") == "roll, pitch, yaw");
    CHECK(read_string_attribute(file, "/devices/index", "device") == "test device");
    CHECK(has_object(file, "/devices/index/sequence") == counters);
    if (counters) CHECK(read_dataset(file, "/devices/index/sequence").values.at(5) == 15.0);

    // row_size: 8 fields (14 values: tick, buttons int64; overrun int8; 11 float64) = 105
    // bytes, and the counters' 2 int64 = 16 more: the stored compound row's size.
    const RowSize size = DeviceRecorder::row_size(counters);
    CHECK(size.values == (counters ? 16u : 14u));
    CHECK(size.bytes == (counters ? 121u : 105u));
    CHECK(inspect::File::open(file).dataset("/devices/index").type.bytes == size.bytes);
  }
}

TEST_CASE("a device table refuses a finger name that cannot be an HDF5 group name", "[device_recorder]") {
  TraceWriter writer(tmp_path("device_bad_name.h5"));
  for (const char* bad : {"", ".", "..", "a/b"}) CHECK_THROWS_AS(DeviceRecorder(writer, bad, 16, false), std::invalid_argument);
  writer.close("complete");
}
