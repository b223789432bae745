// Tests of decimate_trace: the rule a golden is made by. A loop table (/servo, /physics) keeps
// row r exactly when its tick is a multiple of the stride, every value of a kept row bit for bit;
// any other table (/devices/<finger>) and every attribute are copied whole.
#include <catch2/catch.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "graspsim/recordings/trace_decimate.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "tests/support/library.hpp"

using namespace graspsim::recordings;

namespace {

std::string tmp_path(const std::string& name) { return graspsim::test::fresh_tmp_path("recordings_", name); }

// A value with no short binary form, distinct per (tick, column, component).
double value(std::int64_t tick, int column, int component) {
  return static_cast<double>(tick) / 7.0 + column * 10.0 + component / 3.0;
}

// /servo every tick 0..ticks-1, /physics every 4th tick, /devices/index every tick; root
// attributes rate_servo and status.
void write_trace(const std::string& path, std::int64_t ticks) {
  TraceWriter writer(path);
  writer.set_attribute("rate_servo", std::int64_t{1000});
  TraceTable& servo = writer.table("servo");
  TraceTable& physics = writer.table("physics");
  TraceTable& device = writer.table("devices/index");
  for (TraceTable* t : {&servo, &physics, &device}) {
    t->add_column("tick", 1, DType::kInt64, "tick");
    t->add_column("position", 3, DType::kFloat64, "m");
  }
  physics.set_attribute("position", "order", "x, y, z");
  for (std::int64_t tick = 0; tick < ticks; ++tick) {
    for (TraceTable* t : {&servo, &physics, &device}) {
      if (t == &physics && tick % 4 != 0) continue;
      double* row = t->append_row();
      row[0] = static_cast<double>(tick);
      for (int k = 0; k < 3; ++k) row[1 + k] = value(tick, t == &device ? 2 : 1, k);
    }
  }
  writer.close("complete");
}

}  // namespace

TEST_CASE("decimation keeps a loop's rows at multiples of the stride and copies the rest whole",
          "[trace_decimate]") {
  const std::string full = tmp_path("decimate_full.h5");
  const std::int64_t ticks = 50;
  write_trace(full, ticks);
  // Strides that divide the physics period (4), that do not (3), and 1 (a full copy).
  for (const std::int64_t stride : {1, 3, 4, 6}) {
    INFO("stride " << stride);
    const std::string small = tmp_path("decimate_small.h5");
    DecimateOptions options;
    options.stride = stride;
    options.root_strings = {{"golden", "what was kept"}, {"status", "decimated"}};
    decimate_trace(full, small, options);
    CHECK_FALSE(std::filesystem::exists(small + ".part"));

    // Kept: ticks 0, stride, 2 stride, ... of /servo; of /physics (ticks 0, 4, 8, ...) the ones
    // that are also multiples of the stride, i.e. multiples of lcm(4, stride).
    for (const char* table : {"/servo", "/physics"}) {
      const auto tick = read_dataset(small, std::string(table) + "/tick").values;
      const auto position = read_dataset(small, std::string(table) + "/position");
      std::vector<double> expected;
      for (std::int64_t t = 0; t < ticks; ++t)
        if (t % stride == 0 && (std::string(table) == "/servo" || t % 4 == 0)) expected.push_back(static_cast<double>(t));
      INFO(table);
      CHECK(tick == expected);
      REQUIRE(position.shape == std::vector<std::size_t>{expected.size(), 3});
      for (std::size_t r = 0; r < expected.size(); ++r)
        for (int k = 0; k < 3; ++k)   // bit for bit: copied bytes, never recomputed
          CHECK(position.values[3 * r + k] == value(static_cast<std::int64_t>(expected[r]), 1, k));
      CHECK(position.units == "m");
    }
    // Not a loop: every row.
    CHECK(read_dataset(small, "/devices/index/tick").values.size() == static_cast<std::size_t>(ticks));
    // Attributes: copied, then the given root strings, which replace a copied one.
    CHECK(read_int_attribute(small, "/", "rate_servo") == 1000);
    CHECK(read_string_attribute(small, "/physics", "position/order") == "x, y, z");
    CHECK(read_string_attribute(small, "/", "golden") == "what was kept");
    CHECK(read_string_attribute(small, "/", "status") == "decimated");
  }
}

TEST_CASE("decimation refuses a stride below 1 and an input that is not a trace, writing nothing",
          "[trace_decimate]") {
  const std::string full = tmp_path("decimate_refuse_full.h5");
  write_trace(full, 10);
  const std::string small = tmp_path("decimate_refuse_small.h5");
  for (const std::int64_t stride : {0, -3}) {
    DecimateOptions options;
    options.stride = stride;
    CHECK_THROWS_WITH(decimate_trace(full, small, options), Catch::Contains("is not a positive number of ticks"));
  }
  CHECK_THROWS_AS(decimate_trace(tmp_path("no_such_trace.h5"), small, {}), TraceError);
  CHECK_FALSE(std::filesystem::exists(small));
}
