// Tests of TraceRecorder: the engine's tick records land in /servo, /haptic and /physics with
// the documented names, units, row counts and exact values, without allocating.
#include <catch2/catch.hpp>

#include <atomic>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state_hash.hpp"
#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_recorder.hpp"
#include "tests/support/library.hpp"

using namespace graspsim;
using namespace graspsim::recordings;

// Counts C++ heap allocations in this test executable (HDF5's own malloc is not counted).
// GCC cannot see that the replacement operator new below is malloc, and flags the matching
// free() in the inlined operator delete as a mismatch; the pair is consistent.
namespace {
std::atomic<long> g_allocations{0};
}
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
// Every unaligned form is replaced, so no allocation reaches a non-matching deallocation.
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  ++g_allocations;
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new(std::size_t size) {
  if (void* p = operator new(size, std::nothrow)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return operator new(size, std::nothrow);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace {

std::string tmp_path(const std::string& name) { return graspsim::test::fresh_tmp_path("recordings_", name); }

// 2 fingers, 1 box, servo 60 Hz, haptic 12 Hz (every 5th tick), physics 6 Hz (every 10th).
Model small_model() {
  Model m;
  m.rates = Rates{60, 12, 6};
  m.fingers = {FingerParams{"thumb", 500.0}, FingerParams{"index", 400.0}};
  BodyParams box;
  box.name = "box";
  m.bodies = {box};
  return m;
}

// A distinct value for every (tick, finger or body, field, component), with no short binary
// form, so a value written to the wrong place or rounded shows up.
double v(std::int64_t tick, int who, int field, int component) {
  return static_cast<double>(tick) / 7.0 + who * 100.0 + field * 10.0 + component / 3.0;
}
Vec3 v3(std::int64_t tick, int who, int field) {
  return Vec3(v(tick, who, field, 0), v(tick, who, field, 1), v(tick, who, field, 2));
}

// The synthetic record of tick `tick` (haptic_ran when tick % 5 == 0, physics when % 10 == 0).
void fill(TickRecord& rec, std::vector<Vec3>& rendered, std::int64_t tick) {
  rec.tick = tick;
  rec.haptic_ran = tick % 5 == 0;
  rec.physics_ran = tick % 10 == 0;
  for (int i = 0; i < 2; ++i) {
    const auto k = static_cast<std::size_t>(i);
    rec.servo[k].hip = v3(tick, i, 0);
    rec.servo[k].force = v3(tick, i, 1);
    rendered[k] = v3(tick, i, 2);
    HapticFingerRecord& h = rec.haptic[k];
    h.god_object = v3(tick, i, 3);
    h.surface_point = v3(tick, i, 4);
    h.depth = v(tick, i, 5, 0);
    h.friction_radius = v(tick, i, 6, 0);
    h.force = v3(tick, i, 7);
    h.phase = static_cast<ContactPhase>((tick / 5 + i) % 3);
    h.body = static_cast<int>((tick / 5 + i) % 3) - 2;   // -2 floor, -1 none, 0 box
    h.slip = v(tick, i, 8, 0);
  }
  BodyRecord& b = rec.physics[0];
  b.position = v3(tick, 0, 0);
  b.orientation = Quat(v(tick, 0, 1, 0), v(tick, 0, 1, 1), v(tick, 0, 1, 2), v(tick, 0, 1, 3));
  b.velocity = v3(tick, 0, 2);
  b.angular_velocity = v3(tick, 0, 3);
  b.force = v3(tick, 0, 4);
  b.torque = v3(tick, 0, 5);
  b.floor_contacts = static_cast<int>(tick / 10 % 9);
  b.body_contacts = static_cast<int>(tick / 10 % 7);
  b.grasp_area = v(tick, 0, 6, 0);
  b.torsion = v(tick, 0, 6, 1);
  b.twist = v(tick, 0, 6, 2);
}

// The device input of tick `tick` (the gimbal angles are traced) and the State after it (only
// its hash is traced): a state whose tick and first body position follow the tick.
void fill_input(Input& input, std::int64_t tick) {
  for (int i = 0; i < 2; ++i) input.fingers[static_cast<std::size_t>(i)].gimbal = v3(tick, i, 9);
}
void fill_state(State& state, std::int64_t tick) {
  state.tick = tick + 1;
  state.bodies[0].position = v3(tick, 0, 7);
}
Input blank_input() { return make_input(small_model()); }
State blank_state() { return initial_state(small_model()); }

TickRecord blank_record() {
  TickRecord rec;
  rec.servo.resize(2);
  rec.haptic.resize(2);
  rec.physics.resize(1);
  return rec;
}

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// Compares a dataset against expected rows, bit for bit; returns the number of mismatches.
int mismatches(const Dataset& d, const std::vector<double>& expected) {
  if (d.values.size() != expected.size()) return -1;
  int bad = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) bad += bits(d.values[i]) != bits(expected[i]);
  return bad;
}

// Expected contents of a (n, 3) or (n,) column over the ticks that ran.
template <typename F>
std::vector<double> column(const std::vector<std::int64_t>& ticks, int width, F value) {
  std::vector<double> out;
  for (std::int64_t t : ticks) {
    for (int c = 0; c < width; ++c) out.push_back(value(t, c));
  }
  return out;
}

void check(const std::string& file, const std::string& path, std::vector<std::size_t> shape,
           DType dtype, const std::string& units, const std::vector<double>& expected) {
  INFO(path);
  const Dataset d = read_dataset(file, path);
  CHECK(d.shape == shape);
  CHECK(d.dtype == dtype);
  CHECK(d.units == units);
  CHECK(mismatches(d, expected) == 0);
}

}  // namespace

// chunk_ticks: each table's chunk covers that many servo ticks of its loop, rounded up. At
// 60/12/6 Hz (haptic every 5 servo ticks, physics every 10), 25 ticks = 25 /servo rows,
// 5 /haptic rows and ceil(2.5) = 3 /physics rows. Flushed every 25 ticks as the runner does, the
// tick columns still hold every tick of each loop, in order.
TEST_CASE("the recorder sizes each table's chunk to chunk_ticks servo ticks", "[trace_recorder]") {
  const std::string file = tmp_path("recorder_chunks.h5");
  {
    TraceWriter writer(file, TraceOptions{7, 0});
    TraceRecorder recorder(writer, small_model(), 25);
    TickRecord rec = blank_record();
    Input input = blank_input();
    State state = blank_state();
    std::vector<Vec3> rendered(2);
    for (std::int64_t tick = 0; tick < 60; ++tick) {
      fill(rec, rendered, tick);
      fill_input(input, tick);
      fill_state(state, tick);
      recorder.record(rec, rendered, input, state);
      if ((tick + 1) % 25 == 0) writer.flush();
    }
    writer.close("complete");
  }
  const auto chunk_rows = [&](const std::string& path) {
    // Schema 3: the column's chunk is its table's ("/servo" for "/servo/fingers/thumb/hip").
    const inspect::DatasetInfo d = inspect::File::open(file).dataset(path.substr(0, path.find('/', 1)));
    return d.chunk.empty() ? -1 : static_cast<std::int64_t>(d.chunk[0]);
  };
  CHECK(chunk_rows("/servo/tick") == 25);
  CHECK(chunk_rows("/servo/fingers/thumb/hip") == 25);
  CHECK(chunk_rows("/haptic/tick") == 5);
  CHECK(chunk_rows("/physics/tick") == 3);
  CHECK(chunk_rows("/physics/state_hash") == 3);
  for (const auto& [path, step] : {std::pair{std::string("/servo/tick"), 1},
                                   std::pair{std::string("/haptic/tick"), 5},
                                   std::pair{std::string("/physics/tick"), 10}}) {
    std::vector<double> expected;
    for (int t = 0; t < 60; t += step) expected.push_back(t);
    CHECK(read_dataset(file, path).values == expected);
  }
}

// 60 servo ticks at 60/12/6 Hz give 60 /servo rows, 12 /haptic rows (ticks 0, 5, ..., 55) and
// 6 /physics rows (0, 10, ..., 50); every field lands in its documented dataset with its units,
// exactly; time = tick / 60 s; /servo force is the rendered force, force_demand the record's.
// block_rows 7 makes every table cross block boundaries and end on a partial block.
TEST_CASE("the recorder writes the schema with exact values at each loop's rate",
          "[trace_recorder]") {
  const std::string file = tmp_path("recorder.h5");
  const Model model = small_model();
  {
    TraceWriter writer(file, TraceOptions{7, 0});
    TraceRecorder recorder(writer, model);
    TickRecord rec = blank_record();
    Input input = blank_input();
    State state = blank_state();
    std::vector<Vec3> rendered(2);
    for (std::int64_t tick = 0; tick < 60; ++tick) {
      fill(rec, rendered, tick);
      fill_input(input, tick);
      fill_state(state, tick);
      recorder.record(rec, rendered, input, state);
    }
    writer.close("complete");
  }
  std::vector<std::int64_t> servo_ticks, haptic_ticks, physics_ticks;
  for (std::int64_t t = 0; t < 60; ++t) servo_ticks.push_back(t);
  for (std::int64_t t = 0; t < 60; t += 5) haptic_ticks.push_back(t);
  for (std::int64_t t = 0; t < 60; t += 10) physics_ticks.push_back(t);
  REQUIRE(haptic_ticks.size() == 12);
  REQUIRE(physics_ticks.size() == 6);

  const auto tick_of = [](std::int64_t t, int) { return static_cast<double>(t); };
  const auto time_of = [](std::int64_t t, int) { return static_cast<double>(t) / 60.0; };
  for (const auto& [group, ticks] : {std::pair{std::string("/servo"), servo_ticks},
                                     std::pair{std::string("/haptic"), haptic_ticks},
                                     std::pair{std::string("/physics"), physics_ticks}}) {
    check(file, group + "/tick", {ticks.size()}, DType::kInt64, "tick", column(ticks, 1, tick_of));
    check(file, group + "/time", {ticks.size()}, DType::kFloat64, "s", column(ticks, 1, time_of));
  }
  // time is tick / rate, not a running sum of 1/60 (which drifts by tick 59).
  CHECK(read_dataset(file, "/servo/time").values.at(59) == 59.0 / 60.0);

  const std::size_t ns = 60, nh = 12, np = 6;
  const std::string names[2] = {"thumb", "index"};
  for (int i = 0; i < 2; ++i) {
    const std::string s = "/servo/fingers/" + names[i] + "/";
    auto field = [i](int f) { return [i, f](std::int64_t t, int c) { return v(t, i, f, c); }; };
    check(file, s + "hip", {ns, 3}, DType::kFloat64, "m", column(servo_ticks, 3, field(0)));
    check(file, s + "force_demand", {ns, 3}, DType::kFloat64, "N",
          column(servo_ticks, 3, field(1)));
    check(file, s + "force", {ns, 3}, DType::kFloat64, "N", column(servo_ticks, 3, field(2)));
    check(file, s + "gimbal", {ns, 3}, DType::kFloat64, "rad", column(servo_ticks, 3, field(9)));
    CHECK(read_string_attribute(file, s + "gimbal", "order") == "roll, pitch, yaw");

    const std::string h = "/haptic/fingers/" + names[i] + "/";
    auto scalar = [i](int f) { return [i, f](std::int64_t t, int) { return v(t, i, f, 0); }; };
    check(file, h + "god_object", {nh, 3}, DType::kFloat64, "m", column(haptic_ticks, 3, field(3)));
    check(file, h + "surface_point", {nh, 3}, DType::kFloat64, "m",
          column(haptic_ticks, 3, field(4)));
    check(file, h + "depth", {nh}, DType::kFloat64, "m", column(haptic_ticks, 1, scalar(5)));
    check(file, h + "friction_radius", {nh}, DType::kFloat64, "m",
          column(haptic_ticks, 1, scalar(6)));
    check(file, h + "force", {nh, 3}, DType::kFloat64, "N", column(haptic_ticks, 3, field(7)));
    check(file, h + "state", {nh}, DType::kInt8, "1",
          column(haptic_ticks, 1, [i](std::int64_t t, int) { return double((t / 5 + i) % 3); }));
    check(file, h + "body", {nh}, DType::kInt32, "1",
          column(haptic_ticks, 1,
                 [i](std::int64_t t, int) { return double((t / 5 + i) % 3) - 2.0; }));
    check(file, h + "slip", {nh}, DType::kFloat64, "m", column(haptic_ticks, 1, scalar(8)));
    CHECK(read_string_attribute(file, h + "state", "values") == "0 free, 1 stick, 2 slip");
    CHECK(read_string_attribute(file, h + "body", "values") ==
          "-1 none, -2 floor, k = objects[k]");
  }
  CHECK(read_string_attribute(file, "/haptic", "bodies") == "box");

  // The state hash of each physics tick, exact to the bit (uint64, not rounded through double).
  {
    const Dataset hashes = read_dataset(file, "/physics/state_hash");
    CHECK(hashes.dtype == DType::kUInt64);
    CHECK(hashes.shape == std::vector<std::size_t>{np});
    CHECK(hashes.units == "1");
    std::vector<std::uint64_t> expected;
    State state = blank_state();
    for (std::int64_t t : physics_ticks) {
      fill_state(state, t);
      expected.push_back(state_hash(state));
    }
    CHECK(hashes.bits == expected);
  }

  const std::string o = "/physics/objects/box/";
  auto body = [](int f) { return [f](std::int64_t t, int c) { return v(t, 0, f, c); }; };
  check(file, o + "position", {np, 3}, DType::kFloat64, "m", column(physics_ticks, 3, body(0)));
  check(file, o + "quaternion", {np, 4}, DType::kFloat64, "1",
        column(physics_ticks, 4, body(1)));   // Quat(w, x, y, z) was built from components 0..3
  CHECK(read_string_attribute(file, o + "quaternion", "order") == "w, x, y, z");
  check(file, o + "velocity", {np, 3}, DType::kFloat64, "m/s", column(physics_ticks, 3, body(2)));
  check(file, o + "angular_velocity", {np, 3}, DType::kFloat64, "rad/s",
        column(physics_ticks, 3, body(3)));
  check(file, o + "force", {np, 3}, DType::kFloat64, "N", column(physics_ticks, 3, body(4)));
  check(file, o + "torque", {np, 3}, DType::kFloat64, "N m", column(physics_ticks, 3, body(5)));
  check(file, o + "floor_contacts", {np}, DType::kInt32, "1",
        column(physics_ticks, 1, [](std::int64_t t, int) { return double(t / 10 % 9); }));
  check(file, o + "body_contacts", {np}, DType::kInt32, "1",
        column(physics_ticks, 1, [](std::int64_t t, int) { return double(t / 10 % 7); }));
  check(file, o + "grasp_area", {np}, DType::kFloat64, "m^2",
        column(physics_ticks, 1, [](std::int64_t t, int) { return v(t, 0, 6, 0); }));
  check(file, o + "torsion", {np}, DType::kFloat64, "N m",
        column(physics_ticks, 1, [](std::int64_t t, int) { return v(t, 0, 6, 1); }));
  check(file, o + "twist", {np}, DType::kFloat64, "rad",
        column(physics_ticks, 1, [](std::int64_t t, int) { return v(t, 0, 6, 2); }));
}

// A recorder on a run that never ticks still leaves the whole schema, with 0 rows.
TEST_CASE("the recorder declares every dataset before the first tick", "[trace_recorder]") {
  const std::string file = tmp_path("recorder_empty.h5");
  {
    TraceWriter writer(file);
    TraceRecorder recorder(writer, small_model());
    writer.close("complete");
  }
  for (const char* path : {"/servo/tick", "/servo/fingers/index/force_demand",
                           "/haptic/fingers/thumb/slip", "/physics/objects/box/floor_contacts"}) {
    INFO(path);
    CHECK(read_dataset(file, path).shape.at(0) == 0);
  }
  CHECK(read_dataset(file, "/physics/objects/box/quaternion").shape ==
        std::vector<std::size_t>{0, 4});
}

// The servo loop must not allocate (Drake's lesson): once each table has its first row,
// record() makes no C++ heap allocation, even on the ticks where a full block is written.
TEST_CASE("record allocates nothing after the first row, block writes included",
          "[trace_recorder]") {
  const std::string file = tmp_path("recorder_alloc.h5");
  TraceWriter writer(file, TraceOptions{8, 0});
  TraceRecorder recorder(writer, small_model());
  TickRecord rec = blank_record();
  Input input = blank_input();
  State state = blank_state();
  std::vector<Vec3> rendered(2);
  fill(rec, rendered, 0);   // haptic and physics both run on tick 0
  recorder.record(rec, rendered, input, state);
  const long before = g_allocations.load();
  for (std::int64_t tick = 1; tick < 300; ++tick) {   // 37 servo, 7 haptic, 3 physics blocks
    fill(rec, rendered, tick);
    fill_input(input, tick);
    fill_state(state, tick);
    recorder.record(rec, rendered, input, state);
  }
  const long allocations = g_allocations.load() - before;
  CHECK(allocations == 0);
  writer.close("complete");
  CHECK(read_dataset(file, "/servo/tick").shape.at(0) == 300);
}

// Names become HDF5 group names, and records must match the model they were declared for.
TEST_CASE("the recorder refuses unusable names and mismatched records", "[trace_recorder]") {
  const std::string file = tmp_path("recorder_bad.h5");
  {
    Model bad = small_model();
    bad.fingers[1].name = "left/index";
    TraceWriter writer(file);
    CHECK_THROWS_AS(TraceRecorder(writer, bad), std::invalid_argument);
  }
  TraceWriter writer(file);
  TraceRecorder recorder(writer, small_model());
  TickRecord rec = blank_record();
  Input input = blank_input();
  const State state = blank_state();
  std::vector<Vec3> rendered(1);
  CHECK_THROWS_AS(recorder.record(rec, rendered, input, state), std::invalid_argument);
  rendered.resize(2);
  input.fingers.resize(1);
  CHECK_THROWS_AS(recorder.record(rec, rendered, input, state), std::invalid_argument);
  input.fingers.resize(2);
  rec.physics_ran = true;
  rec.physics.clear();
  CHECK_THROWS_AS(recorder.record(rec, rendered, input, state), std::invalid_argument);
  writer.close("complete");
}

// row_sizes, which the run's memory and disk estimate uses (app/run_budget.cpp), is the
// rows the constructor declares: for 1 to 3 fingers and 0 to 3 bodies, each table's doubles per
// row equal TraceTable::row_width() and its bytes per row the stored compound type's size.
TEST_CASE("row_sizes counts the doubles and bytes of every row the recorder declares", "[trace_recorder]") {
  for (std::size_t fingers = 1; fingers <= 3; ++fingers) {
    for (std::size_t bodies = 0; bodies <= 3; ++bodies) {
      Model m;
      m.rates = Rates{60, 12, 6};
      const char* finger_names[] = {"thumb", "index", "middle"};
      const char* body_names[] = {"box", "rod", "ring"};
      for (std::size_t f = 0; f < fingers; ++f) m.fingers.push_back(FingerParams{finger_names[f], 500.0});
      for (std::size_t b = 0; b < bodies; ++b) {
        BodyParams body;
        body.name = body_names[b];
        m.bodies.push_back(body);
      }
      INFO(fingers << " fingers, " << bodies << " bodies");
      const std::string file = tmp_path("row_sizes.h5");
      const TraceRecorder::Rows rows = TraceRecorder::row_sizes(m);
      {
        TraceWriter writer(file);
        TraceRecorder recorder(writer, m);
        CHECK(writer.table("servo").row_width() == rows.servo.values);
        CHECK(writer.table("haptic").row_width() == rows.haptic.values);
        CHECK(writer.table("physics").row_width() == rows.physics.values);
        writer.close("complete");
      }
      const inspect::File f = inspect::File::open(file);
      for (const auto& [table, size] : {std::pair{"/servo", rows.servo}, std::pair{"/haptic", rows.haptic},
                                        std::pair{"/physics", rows.physics}}) {
        INFO(table);
        CHECK(f.dataset(table).type.bytes == size.bytes);
      }
    }
  }
}
