// Traces as big as the scenes (recordings/README.md "Schema"): a run of 1000 bodies, and one of
// 100 fingers, each traced, read back through the reader, compared with itself and with its
// replay bit for bit, and loaded by the viewer (`graspsim view`'s scene and packer). The rows keep
// one member per group however many bodies or fingers there are. The scene is
// tests/e2e/data/many_bodies.lua; python/tests/test_big_trace.py reads the same scene from Python.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "app/replay.hpp"
#include "app/run.hpp"
#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_compare.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_recorder.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "view/server/pack.hpp"
#include "view/server/scene.hpp"

using namespace graspsim;

namespace {

const std::string kScene = std::string(GRASPSIM_SOURCE_DIR) + "/tests/e2e/data/many_bodies.lua";
const std::string kTmp = GRASPSIM_TEST_TMP;

// Runs many_bodies.lua with `sets` to `out`, tracing every loop.
app::RunResult run_scene(const std::vector<std::string>& sets, const std::string& out) {
  scripting::LoadOptions load;
  load.sets = sets;
  const auto scenario = scripting::Scenario::load(kScene, load);
  app::RunOptions options;
  options.out = out;
  options.overrides = sets;
  return app::run_scenario(scenario, options);
}

// The trace compared with itself, bitwise: every column of every table, `columns` of them.
void compare_with_itself(const std::string& trace, std::size_t columns) {
  recordings::CompareOptions bitwise;
  bitwise.bitwise = true;
  const recordings::CompareResult self = recordings::compare_traces(trace, trace, bitwise);
  CHECK(self.same());
  CHECK(self.datasets.size() == columns);
}

// Replayed from its own /servo rows: the replay's trace equals it bit for bit, state hash included.
void replay_equals(const std::string& trace, const std::string& out, std::int64_t physics_rows) {
  const app::ReplayPlan plan = app::load_replay(trace);
  const app::ReplayOutcome outcome = app::run_replay(plan, plan.run_options(out));
  INFO(outcome.run.error << outcome.compare_error);
  REQUIRE(outcome.comparison.has_value());
  CHECK(outcome.comparison->same());
  CHECK(outcome.comparison->schema_version == recordings::kSchemaVersion);
  CHECK(outcome.state_hashes() == physics_rows);
}

}  // namespace

TEST_CASE("a trace of 1000 bodies is written, read, compared, replayed and shown", "[e2e][trace][big]") {
  const std::string trace = kTmp + "/big_bodies.h5";
  const app::RunResult run = run_scene({"objects=1000"}, trace);
  REQUIRE(run.error.empty());
  REQUIRE(run.physics_ticks == 5);   // 0.1 s at 50 Hz

  // The row type stays small: tick, time, state_hash and one member for all 1000 objects.
  const recordings::inspect::DatasetInfo physics = recordings::inspect::File::open(trace).dataset("/physics");
  REQUIRE(physics.members.size() == 4);
  CHECK(physics.members[3].name == "objects");
  CHECK(physics.members[3].width == 1000);
  CHECK(physics.members[3].fields.size() == 11);

  // Read back: every column in one pass, and one column alone, the same values.
  const recordings::Table table = recordings::read_table(trace, "/physics");
  CHECK(table.names.size() == 3 + 1000 * 11);
  const recordings::Dataset& last = table.column("objects/box999/position");
  REQUIRE(last.shape == std::vector<std::size_t>{5, 3});
  CHECK(last.units == "m");
  CHECK(last.values == recordings::read_dataset(trace, "/physics/objects/box999/position").values);
  // The boxes rest where they were put: box 999 of a 32 x 32 grid 0.3 m apart, row 31, column 7.
  CHECK(last.values[0] == Approx((7 - 15.5) * 0.3).margin(1e-9));
  CHECK(last.values[1] == Approx((31 - 15.5) * 0.3).margin(1e-9));
  CHECK(table.column("objects/box0/floor_contacts").dtype == recordings::DType::kInt32);
  CHECK(recordings::read_string_attribute(trace, "/physics/objects/box500/quaternion", "order") == "w, x, y, z");
  const std::vector<std::string> paths = recordings::list_datasets(trace);
  CHECK(std::count_if(paths.begin(), paths.end(), [](const std::string& p) { return p.rfind("/physics/", 0) == 0; }) ==
        3 + 1000 * 11);

  // Compared with itself (servo and haptic time, physics time and state hash, 11000 body columns).
  compare_with_itself(trace, 1 + 1 + 2 + 1000 * 11);

  // Shown: the viewer's scene has every body's poses, and the page's packer takes them.
  const view::ViewScene scene = view::load_scene(trace);
  REQUIRE(scene.bodies.size() == 1000);
  CHECK(scene.bodies[999].position == last.values);
  CHECK(scene.physics_tick.size() == 5);
  const view::Packed packed = view::pack_scene(scene);
  CHECK(packed.json.find("\"box999\"") != std::string::npos);

  replay_equals(trace, kTmp + "/big_bodies.replay.h5", 5);
}

TEST_CASE("a trace of 100 fingers is written, read, compared, replayed and shown", "[e2e][trace][big]") {
  const std::string trace = kTmp + "/big_fingers.h5";
  const app::RunResult run = run_scene({"objects=4", "fingers=100"}, trace);
  REQUIRE(run.error.empty());
  REQUIRE(run.servo_ticks == 300);

  // One member for all 100 fingers in /servo and in /haptic.
  const recordings::inspect::File file = recordings::inspect::File::open(trace);
  for (const char* t : {"/servo", "/haptic"}) {
    const recordings::inspect::DatasetInfo d = file.dataset(t);
    REQUIRE(d.members.size() == 3);
    CHECK(d.members[2].name == "fingers");
    CHECK(d.members[2].width == 100);
  }

  // Every finger's columns, read in one pass of each table; the fingers press on the boxes.
  const recordings::Table servo = recordings::read_table(trace, "/servo");
  const recordings::Table haptic = recordings::read_table(trace, "/haptic");
  CHECK(servo.names.size() == 2 + 100 * 4);
  CHECK(haptic.names.size() == 2 + 100 * 8);
  CHECK(servo.column("fingers/f99/hip").shape == std::vector<std::size_t>{300, 3});
  const recordings::Dataset& body = haptic.column("fingers/f99/body");
  REQUIRE(body.shape == std::vector<std::size_t>{50});
  CHECK(body.dtype == recordings::DType::kInt32);
  CHECK(body.values.back() == 3.0);   // finger 99 presses on the fourth box
  CHECK(haptic.column("fingers/f0/state").values.back() != 0.0);
  CHECK(recordings::read_string_attribute(trace, "/servo/fingers/f42/gimbal", "order") == "roll, pitch, yaw");

  compare_with_itself(trace, (1 + 100 * 4) + (1 + 100 * 8) + (2 + 4 * 11));   // servo, haptic, physics

  const view::ViewScene scene = view::load_scene(trace);
  REQUIRE(scene.fingers.size() == 100);
  REQUIRE(scene.haptic_tick.size() == 41);   // up to the last physics tick, 240
  CHECK(scene.fingers[99].hip.size() == 3 * 41);
  CHECK(view::pack_scene(scene).json.find("\"f99\"") != std::string::npos);

  replay_equals(trace, kTmp + "/big_fingers.replay.h5", 5);
}
