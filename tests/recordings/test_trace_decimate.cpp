// Tests of decimate_trace: the rule a golden is made by. A loop table (/servo, /physics) keeps
// row r exactly when its tick is a multiple of the stride, every value of a kept row bit for bit;
// any other table (/devices/<finger>) and every attribute are copied whole.
#include <catch2/catch.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "graspsim/recordings/record_selection.hpp"
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

TEST_CASE("a decimated trace's record attribute says which ticks it holds", "[trace_decimate]") {
  // Law: a loop of period d servo ticks, recorded every e-th of its ticks, keeps at the servo
  // ticks that are multiples of the stride S every lcm(e, S / gcd(S, d))-th of its ticks. A
  // golden of a 3000 / 500 / 50 Hz run at S = 60: servo every 60th, haptic (d = 6) every 10th,
  // physics (d = 60) every one; at S = 6 of a 3000 / 500 / 1000 Hz run, physics (d = 3) every
  // 2nd. /devices is copied whole. Checked against the rows the copy actually holds.
  CHECK(RecordSelection{}.thinned(60, {1, 6, 60}).text() == "servo:60,haptic:10,physics:1,devices:1");
  CHECK(RecordSelection{}.thinned(6, {1, 6, 3}).text() == "servo:6,haptic:1,physics:2,devices:1");
  CHECK(RecordSelection::parse("physics:4").thinned(6, {1, 6, 3}).text() == "physics:4");
  CHECK(RecordSelection::parse("servo:4,haptic:3").thinned(6, {1, 6, 3}).text() == "servo:12,haptic:3");

  const std::string full = tmp_path("decimate_record_full.h5");
  const std::int64_t ticks = 60;
  {
    TraceWriter writer(full);
    writer.set_attribute("rate_servo", std::int64_t{1200});
    writer.set_attribute("rate_haptic", std::int64_t{300});   // d = 4
    writer.set_attribute("rate_physics", std::int64_t{400});  // d = 3
    TraceTable& servo = writer.table("servo");
    TraceTable& haptic = writer.table("haptic");
    TraceTable& physics = writer.table("physics");
    for (TraceTable* t : {&servo, &haptic, &physics}) t->add_column("tick", 1, DType::kInt64, "tick");
    for (std::int64_t tick = 0; tick < ticks; ++tick) {
      servo.append_row()[0] = static_cast<double>(tick);
      if (tick % 4 == 0) haptic.append_row()[0] = static_cast<double>(tick);
      if (tick % 3 == 0) physics.append_row()[0] = static_cast<double>(tick);
    }
    writer.close("complete");
  }
  const std::string small = tmp_path("decimate_record_small.h5");
  DecimateOptions options;
  options.stride = 10;
  decimate_trace(full, small, options);
  const RecordSelection held = RecordSelection::from_attribute(read_string_attribute(small, "/", "record"));
  // servo every 10th, haptic every lcm(1, 10 / 2) = 5th, physics every 10 / 1 = 10th.
  CHECK(held.text() == "servo:10,haptic:5,physics:10,devices:1");
  const std::array<std::int64_t, 3> period{1, 4, 3};
  const char* tables[] = {"/servo/tick", "/haptic/tick", "/physics/tick"};
  for (std::size_t l = 0; l < 3; ++l) {
    INFO(tables[l]);
    const std::int64_t step = held.every[l] * period[l];   // servo ticks between kept rows
    std::vector<double> expected;
    for (std::int64_t t = 0; t < ticks; t += step) expected.push_back(static_cast<double>(t));
    CHECK(read_dataset(small, tables[l]).values == expected);
  }
}
