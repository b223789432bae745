// A run's memory and disk, estimated before it starts (app/run_budget.hpp): the estimate
// against what a run actually writes, and the refusal when a machine cannot hold it.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "app/run.hpp"
#include "app/run_budget.hpp"
#include "graspsim/hw/replay_device.hpp"
#include "graspsim/hw/scripted_finger.hpp"
#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/scripting/scenario.hpp"

using namespace graspsim;
using Catch::Matchers::Contains;

namespace {

const std::string kLift = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/two_finger_lift.lua";
const std::string kTmp = GRASPSIM_TEST_TMP;

scripting::Scenario lift(const std::vector<std::string>& sets) {
  scripting::LoadOptions load;
  load.sets = sets;
  return scripting::Scenario::load(kLift, load);
}

// What the file holds for a table: the bytes its chunks take, one chunk's bytes, one row's bytes.
struct Stored {
  double storage = 0.0, chunk = 0.0, row = 0.0;   // bytes
};
Stored stored(const std::string& file, const std::string& table) {
  const recordings::inspect::DatasetInfo d = recordings::inspect::File::open(file).dataset(table);
  REQUIRE(d.chunk.size() == 1);
  return Stored{static_cast<double>(d.storage_bytes), static_cast<double>(d.chunk[0] * d.type.bytes),
                static_cast<double>(d.type.bytes)};
}

std::vector<hw::Vec3> rows(const recordings::Dataset& d) {
  std::vector<hw::Vec3> out;
  for (std::size_t i = 0; i + 2 < d.values.size(); i += 3) out.emplace_back(d.values[i], d.values[i + 1], d.values[i + 2]);
  return out;
}

}  // namespace

// The disk estimate is the rows' stored bytes: an uncompressed table allocates whole chunks, so
// its storage S holds the estimate E with at most one chunk C to spare: E <= S < E + C, per table,
// and each table's row is the stored compound type's size exactly. Swept over three durations of
// the lift (1.5 s, 2.34 s: a partly filled last chunk, 4 s), and with one finger on a replayed
// device (its /devices table, 121-byte rows with the counters: DeviceRecorder::row_size, the
// sum of its field tables, against the table the runner wrote through it).
TEST_CASE("the disk estimate is every table's rows at their stored size, within one chunk of the file's "
          "storage", "[e2e][run_budget]") {
  const scripting::Scenario recorded = lift({});
  app::RunOptions record;
  record.out = kTmp + "/budget_recorded.h5";
  REQUIRE(app::run_scenario(recorded, record).error.empty());
  const recordings::Dataset hip = recordings::read_dataset(record.out, "/servo/fingers/thumb/hip");
  const recordings::Dataset gimbal = recordings::read_dataset(record.out, "/servo/fingers/thumb/gimbal");
  for (const char* duration : {"1.5", "2.34", "4"}) {
    for (bool device : {false, true}) {
      INFO("duration " << duration << " s, device table " << device);
      const scripting::Scenario scenario = lift({std::string("duration=") + duration});
      app::RunOptions options;
      options.out = kTmp + "/budget_run.h5";
      if (device) {
        options.devices.record = {true, false};
        options.devices.make = [&](std::size_t f) -> std::unique_ptr<hw::Device> {
          if (f == 1) return std::make_unique<hw::ScriptedFinger>(scenario.make_trajectory(1), scenario.fingers()[1].limits);
          return std::make_unique<hw::ReplayDevice>(rows(hip), rows(gimbal), scenario.fingers()[0].limits, "recording");
        };
      }
      const app::RunFootprint need = app::estimate_footprint(scenario, options);
      const app::RunResult result = app::run_scenario(scenario, options);
      INFO(result.error);
      REQUIRE(result.error.empty());
      CHECK(need.servo_ticks == result.servo_ticks);
      CHECK(need.tables.size() == (device ? 4u : 3u));
      double total = 0.0;
      for (const app::TableFootprint& t : need.tables) {
        const Stored s = stored(options.out, t.name);
        const double estimate = t.rows * static_cast<double>(t.bytes);
        INFO(t.name << ": estimate " << estimate << " bytes, stored " << s.storage << ", chunk " << s.chunk);
        CHECK(static_cast<double>(t.bytes) == s.row);
        CHECK(estimate <= s.storage);
        CHECK(s.storage < estimate + s.chunk);
        total += estimate;
      }
      CHECK(need.disk == total);
      if (device) CHECK(need.tables.back().name == "/devices/thumb");
      if (device) CHECK(need.tables.back().bytes == 121u);
    }
  }
}

// The memory estimate, derived by hand for the lift at 3000 / 500 / 50 Hz: a flush interval is
// 360 servo ticks (the whole physics periods within 0.12 s), so blocks of 360 / 60 / 6 rows of
// 26 / 30 / 27 doubles, held 4 times with the writer thread, plus one packed block of
// 208 / 218 / 208 bytes a row:
//   4 x 8 x (360 x 26 + 60 x 30 + 6 x 27) + 360 x 208 + 60 x 218 + 6 x 208 = 451,512 bytes.
// At 30000 / 5000 / 50 Hz the interval is 3600 ticks: the servo and haptic blocks 10 times
// longer, the physics block the same 6 rows:
//   4 x 8 x (3600 x 26 + 600 x 30 + 6 x 27) + 3600 x 208 + 600 x 218 + 6 x 208 = 4,457,232.
// Without the writer thread 1 block is held. Exact: these are integer counts.
TEST_CASE("the memory estimate is the writer's blocks of one flush interval per table", "[e2e][run_budget]") {
  app::RunOptions options;
  const app::RunFootprint base = app::estimate_footprint(lift({}), options);
  CHECK(base.memory == 451512.0);
  CHECK(base.servo_ticks == 12000);
  CHECK(app::estimate_footprint(lift({"rates.servo=30000", "rates.haptic=5000"}), options).memory == 4457232.0);
  options.trace.background_writer = false;
  CHECK(app::estimate_footprint(lift({}), options).memory == 8.0 * (360 * 26 + 60 * 30 + 6 * 27) + 360 * 208 + 60 * 218 + 6 * 208);
  CHECK_THAT(base.memory_detail, Contains("/servo: 4 blocks of 360 rows of 26 values"));
}

// The refusal names both figures: memory over what is available refuses; disk over what is free
// refuses an uncompressed trace and only warns for a compressed one (its size is not known); a
// run that fits is not refused, nor one whose room is unknown (negative).
TEST_CASE("a run is refused when its memory or its uncompressed disk will not fit, naming both figures",
          "[e2e][run_budget]") {
  app::RunFootprint need;
  need.servo_ticks = 259200000;
  need.memory = 3.0e9;
  need.disk = 6.4e10;
  need.memory_detail = "/servo: 4 blocks";
  std::string warning;
  CHECK(app::refusal(need, app::MachineRoom{4e9, 1e11}, 0, &warning).empty());
  CHECK(app::refusal(need, app::MachineRoom{-1.0, -1.0}, 0, &warning).empty());
  CHECK(warning.empty());
  CHECK_THAT(app::refusal(need, app::MachineRoom{2e9, 1e11}, 0, &warning),
             Contains("need 3.0 GB of memory (/servo: 4 blocks), and this machine has 2.0 GB available"));
  CHECK_THAT(app::refusal(need, app::MachineRoom{4e9, 5e10}, 0, &warning),
             Contains("the trace needs about 64.0 GB of disk (259200000 servo ticks") &&
                 Contains("its directory has 50.0 GB free"));
  CHECK(app::refusal(need, app::MachineRoom{4e9, 5e10}, 6, &warning).empty());
  CHECK_THAT(warning, Contains("compressed it may fit"));
}

// A table whose chunk (one flush interval of its rows) would pass HDF5's 4 GiB chunk limit is
// refused whatever the machine has, naming the table and the limit: 360 /servo rows of 96 bytes
// a finger pass it at 124,276 fingers (recordings/README.md "Limits").
TEST_CASE("a run whose trace table would need chunks over HDF5's 4 GiB is refused, naming the table",
          "[e2e][run_budget]") {
  app::RunFootprint need;
  need.tables.push_back({"/servo", 12 * 124276 + 2, 96 * 124276 + 16, 360.0, 12000.0});
  std::string warning;
  CHECK_THAT(app::refusal(need, app::MachineRoom{-1.0, -1.0}, 0, &warning),
             Contains("/servo table would need chunks of 4.3 GB (360 rows of 11.9 MB)") &&
                 Contains("HDF5's limit of 4.3 GB (2^32 - 1 bytes) a chunk"));
  need.tables.back().values = 12 * 124275 + 2;
  need.tables.back().bytes = 96 * 124275 + 16;
  CHECK(app::refusal(need, app::MachineRoom{-1.0, -1.0}, 0, &warning).empty());
}
