// Tests of compare_traces on small synthetic traces written by TraceWriter and edited in place
// through the schema-free HDF5 view (h5_inspect.hpp): alignment by tick, the first divergence
// located by tick, time, dataset, object or finger and component, tolerances (global, per
// dataset, glob), bitwise mode, and every kind of unusable input.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_compare.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "tests/support/trace_edit.hpp"

using namespace graspsim::recordings;

namespace {

std::string tmp_path(const std::string& name) {
  const std::string path = std::string(GRASPSIM_TEST_TMP) + "/compare_" + name;
  std::remove(path.c_str());
  return path;
}

struct Spec {
  int rate_servo = 1200, rate_haptic = 600, rate_physics = 300;   // Hz
  std::int64_t servo_ticks = 240;   // 0.2 s
  int physics_every = 1;            // keep every k-th physics row (decimation)
  bool extra_dataset = false;       // add physics/objects/box/extra
  int quaternion_width = 4;
  std::int64_t schema_version = 1;
  bool with_schema = true;
  std::string version = "v1";
};

// A trace shaped like graspsim's: a finger "thumb" and an object "box"; values are smooth
// functions of the tick, with one NaN column so NaN handling is exercised.
void make_trace(const std::string& path, const Spec& s) {
  TraceWriter w(path);
  if (s.with_schema) w.set_attribute("schema_version", s.schema_version);
  w.set_attribute("rate_servo", s.rate_servo);
  w.set_attribute("rate_haptic", s.rate_haptic);
  w.set_attribute("rate_physics", s.rate_physics);
  w.set_attribute("graspsim_version", s.version);
  w.set_attribute("seed", 7);
  TraceTable& servo = w.table("servo");
  const std::size_t s_tick = servo.add_column("tick", 1, DType::kInt64, "tick");
  const std::size_t s_time = servo.add_column("time", 1, DType::kFloat64, "s");
  const std::size_t s_force = servo.add_column("fingers/thumb/force", 3, DType::kFloat64, "N");
  TraceTable& haptic = w.table("haptic");
  const std::size_t h_tick = haptic.add_column("tick", 1, DType::kInt64, "tick");
  const std::size_t h_time = haptic.add_column("time", 1, DType::kFloat64, "s");
  const std::size_t h_state = haptic.add_column("fingers/thumb/state", 1, DType::kInt8, "1");
  const std::size_t h_depth = haptic.add_column("fingers/thumb/depth", 1, DType::kFloat64, "m");
  TraceTable& physics = w.table("physics");
  const std::size_t p_tick = physics.add_column("tick", 1, DType::kInt64, "tick");
  const std::size_t p_time = physics.add_column("time", 1, DType::kFloat64, "s");
  const std::size_t p_pos = physics.add_column("objects/box/position", 3, DType::kFloat64, "m");
  const std::size_t p_q =
      physics.add_column("objects/box/quaternion", s.quaternion_width, DType::kFloat64, "1");
  physics.set_attribute("objects/box/quaternion", "order", "w, x, y, z");
  const std::size_t p_extra =
      s.extra_dataset ? physics.add_column("objects/box/extra", 1, DType::kFloat64, "1") : 0;
  const int haptic_every = s.rate_servo / s.rate_haptic;
  const int physics_every = s.rate_servo / s.rate_physics;
  std::int64_t physics_row = 0;
  for (std::int64_t t = 0; t < s.servo_ticks; ++t) {
    const double time = static_cast<double>(t) / s.rate_servo;
    double* r = servo.append_row();
    r[s_tick] = static_cast<double>(t);
    r[s_time] = time;
    for (int j = 0; j < 3; ++j) r[s_force + j] = std::sin(time + j);
    if (t % haptic_every == 0) {
      double* h = haptic.append_row();
      h[h_tick] = static_cast<double>(t);
      h[h_time] = time;
      h[h_state] = static_cast<double>(t / haptic_every % 3);
      h[h_depth] = t % 5 == 0 ? std::numeric_limits<double>::quiet_NaN() : 1e-3 * time;
    }
    if (t % physics_every == 0 && (physics_row++ % s.physics_every) == 0) {
      double* p = physics.append_row();
      p[p_tick] = static_cast<double>(t);
      p[p_time] = time;
      p[p_pos + 0] = 0.01 * time;
      p[p_pos + 1] = -0.02 * time;
      p[p_pos + 2] = 0.08 + 0.1 * time * time;
      for (int j = 0; j < s.quaternion_width; ++j) p[p_q + j] = j == 0 ? 1.0 : 0.0;
      if (s.extra_dataset) p[p_extra] = 1.0;
    }
  }
  w.close("complete");
}

using graspsim::test::get_element;
using graspsim::test::set_element;

// A pair of identical traces, A and B.
std::pair<std::string, std::string> twins(const std::string& name, const Spec& s = {}) {
  const std::string a = tmp_path(name + "_a.h5"), b = tmp_path(name + "_b.h5");
  make_trace(a, s);
  make_trace(b, s);
  return {a, b};
}

const DatasetResult& dataset(const CompareResult& r, const std::string& path) {
  for (const DatasetResult& d : r.datasets)
    if (d.path == path) return d;
  FAIL("no dataset " << path);
  throw;
}

std::string input_error(const std::string& a, const std::string& b, const CompareOptions& o = {}) {
  try {
    compare_traces(a, b, o);
  } catch (const CompareInputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("identical traces compare equal, bitwise and by value", "[compare]") {
  const auto [a, b] = twins("identical");
  CompareOptions bitwise;
  bitwise.bitwise = true;
  for (const CompareOptions& o : {CompareOptions{}, bitwise}) {
    const CompareResult r = compare_traces(a, b, o);
    CHECK(r.same());
    CHECK(r.differing_datasets() == 0);
    CHECK(r.schema_version == 1);
    CHECK(r.rate_servo == 1200);
    // Every dataset except the three tick columns: servo time+force, haptic time+state+depth,
    // physics time+position+quaternion.
    CHECK(r.datasets.size() == 8);
    REQUIRE(r.loops.size() == 3);
    CHECK(r.loops[0].loop == "servo");
    CHECK(r.loops[0].matched == 240);
    CHECK(r.loops[1].matched == 120);
    CHECK(r.loops[2].matched == 60);
    for (const auto& l : r.loops) CHECK(l.only_a + l.only_b == 0);
    // The depth column holds NaNs at the same places with the same bits: equal in both modes.
    CHECK(dataset(r, "haptic/fingers/thumb/depth").exceeded == 0);
    CHECK(dataset(r, "haptic/fingers/thumb/depth").max_abs_error == 0.0);
  }
}

// The acceptance case of compare: one element changed by 1e-9 is found at its tick, time,
// dataset, object and component.
TEST_CASE("a 1e-9 change is found at its tick, time, object and component", "[compare]") {
  const auto [a, b] = twins("one_change");
  // Physics row 25 = servo tick 100 (physics every 4 servo ticks), t = 100/1200 s; z = column 2.
  const double before = get_element(b, "/physics/objects/box/position", 25, 2);
  set_element(b, "/physics/objects/box/position", 25, 2, before + 1e-9);
  const double after = get_element(b, "/physics/objects/box/position", 25, 2);
  const double change = after - before;   // 1e-9 up to the rounding of `before + 1e-9`
  CHECK(change == Approx(1e-9).epsilon(1e-6));

  const CompareResult r = compare_traces(a, b);
  CHECK_FALSE(r.same());
  CHECK(r.differing_datasets() == 1);
  const DatasetResult& d = r.datasets.front();   // the differing one is listed first
  CHECK(d.path == "physics/objects/box/position");
  CHECK(d.loop == "physics");
  CHECK(d.kind == "object");
  CHECK(d.name == "box");
  CHECK(d.quantity == "position");
  CHECK(d.units == "m");
  REQUIRE(d.first);
  CHECK(d.first->tick == 100);
  CHECK(d.first->time == 100.0 / 1200.0);
  CHECK(d.components.at(d.first->component) == "z");
  CHECK(d.first->a == before);
  CHECK(d.first->b == after);
  CHECK(d.first->abs_error == change);
  CHECK(d.first->rel_error == change / after);
  CHECK(d.exceeded == 1);
  CHECK(d.elements == 60 * 3);
  CHECK(d.max_abs_error == change);

  // A tolerance above the change passes; one below it does not.
  CompareOptions loose;
  loose.tolerance.atol = 2e-9;
  CHECK(compare_traces(a, b, loose).same());
  CompareOptions tight;
  tight.tolerance.atol = 0.5e-9;
  CHECK_FALSE(compare_traces(a, b, tight).same());
  // Relative: |change| / |value| is about 1.2e-8 (value about 0.0807 m).
  CompareOptions relative;
  relative.tolerance.rtol = 2e-8;
  CHECK(compare_traces(a, b, relative).same());
  relative.tolerance.rtol = 0.5e-8;
  CHECK_FALSE(compare_traces(a, b, relative).same());
}

TEST_CASE("a per-dataset tolerance overrides the global one, with glob patterns", "[compare]") {
  const auto [a, b] = twins("per_dataset");
  set_element(b, "/physics/objects/box/position", 10, 0, get_element(b, "/physics/objects/box/position", 10, 0) + 1e-6);
  set_element(b, "/servo/fingers/thumb/force", 3, 1, get_element(b, "/servo/fingers/thumb/force", 3, 1) + 1e-3);

  // Only the position loosened: the force still differs.
  CompareOptions o;
  o.rules = {{"physics/objects/box/position", {1e-5, 0.0}}};
  CompareResult r = compare_traces(a, b, o);
  CHECK(r.differing_datasets() == 1);
  CHECK(r.datasets.front().path == "servo/fingers/thumb/force");
  CHECK(dataset(r, "physics/objects/box/position").rule == "physics/objects/box/position");
  CHECK(dataset(r, "physics/objects/box/position").tolerance.atol == 1e-5);

  // Both loosened, by a glob that crosses '/' and a leading '/' that is ignored.
  o.rules.push_back({"/servo/*", {1e-2, 0.0}});
  CHECK(compare_traces(a, b, o).same());

  // A global tolerance that passes everything, overridden for the box only: the box differs.
  CompareOptions g;
  g.tolerance.atol = 1e-2;
  g.rules = {{"physics/objects/box/*", {1e-9, 0.0}}};
  r = compare_traces(a, b, g);
  CHECK(r.differing_datasets() == 1);
  CHECK(r.datasets.front().path == "physics/objects/box/position");
  // The last matching rule wins.
  g.rules.push_back({"*/position", {1e-5, 0.0}});
  CHECK(compare_traces(a, b, g).same());

  // A pattern that matches nothing is an input error naming it.
  CompareOptions typo;
  typo.rules = {{"physics/objects/bx/position", {1.0, 0.0}}};
  CHECK_THAT(input_error(a, b, typo), Catch::Contains("'physics/objects/bx/position' matches no dataset"));

  CHECK(tolerance_pattern_matches("servo/*", "servo/fingers/thumb/force"));
  CHECK(tolerance_pattern_matches("*/force", "haptic/fingers/index/force"));
  CHECK_FALSE(tolerance_pattern_matches("servo/*", "haptic/fingers/thumb/force"));
}

TEST_CASE("differing datasets are sorted by first divergence, not by name", "[compare]") {
  const auto [a, b] = twins("order");
  // Physics (listed last by name order) first diverges at servo tick 40, the servo force at
  // tick 200, the haptic state at tick 120.
  set_element(b, "/physics/objects/box/quaternion", 10, 3, 1e-12);
  set_element(b, "/physics/objects/box/quaternion", 50, 1, 1e-12);
  set_element(b, "/servo/fingers/thumb/force", 200, 0, 5.0);
  set_element(b, "/haptic/fingers/thumb/state", 60, 0, 2.0);   // was 60 % 3 = 0
  const CompareResult r = compare_traces(a, b);
  REQUIRE(r.differing_datasets() == 3);
  CHECK(r.datasets[0].path == "physics/objects/box/quaternion");
  CHECK(r.datasets[0].first->tick == 40);
  CHECK(r.datasets[0].components.at(r.datasets[0].first->component) == "z");   // from "order"
  CHECK(r.datasets[0].exceeded == 2);
  CHECK(r.datasets[1].path == "haptic/fingers/thumb/state");
  CHECK(r.datasets[1].first->tick == 120);
  CHECK(r.datasets[1].kind == "finger");
  CHECK(r.datasets[1].name == "thumb");
  CHECK(r.datasets[1].integer);
  CHECK(r.datasets[2].path == "servo/fingers/thumb/force");
  CHECK(r.datasets[2].first->tick == 200);
  CHECK(r.datasets[2].components.at(r.datasets[2].first->component) == "x");
}

TEST_CASE("rows are aligned by tick: decimated and shorter traces compare where ticks match", "[compare]") {
  const std::string a = tmp_path("full.h5"), half = tmp_path("half.h5"), short_b = tmp_path("short.h5");
  make_trace(a, Spec{});
  Spec decimated;
  decimated.physics_every = 2;   // physics ticks 0, 8, 16, ...
  make_trace(half, decimated);
  Spec shorter;
  shorter.servo_ticks = 100;
  make_trace(short_b, shorter);

  CompareResult r = compare_traces(a, half);
  CHECK(r.same());
  CHECK(r.loops[2].rows_a == 60);
  CHECK(r.loops[2].rows_b == 30);
  CHECK(r.loops[2].matched == 30);
  CHECK(r.loops[2].only_a == 30);
  CHECK(r.loops[2].only_b == 0);
  REQUIRE(r.loops[2].first_only_a);
  CHECK(*r.loops[2].first_only_a == 4);
  // A change at a tick the decimated trace holds is found at that tick (physics row 6 of the
  // decimated trace = row 12 of the full one = servo tick 48) ...
  set_element(half, "/physics/objects/box/position", 6, 1, 1.0);
  r = compare_traces(a, half);
  REQUIRE(r.differing_datasets() == 1);
  CHECK(r.datasets.front().first->tick == 48);
  // ... and ticks in one trace only count only when asked.
  CompareOptions strict;
  strict.all_ticks = true;
  CHECK_FALSE(compare_traces(a, short_b, strict).same());
  r = compare_traces(a, short_b);
  CHECK(r.same());
  CHECK(r.loops[0].only_a == 140);
  CHECK(*r.loops[0].first_only_a == 100);
  CHECK(r.unmatched_ticks() == 140 + 70 + 35);
}

TEST_CASE("bitwise mode tells -0 from 0 and NaN payloads apart, value mode does not", "[compare]") {
  const auto [a, b] = twins("bitwise");
  set_element(a, "/servo/fingers/thumb/force", 0, 0, 0.0);
  set_element(b, "/servo/fingers/thumb/force", 0, 0, -0.0);
  CHECK(compare_traces(a, b).same());
  CompareOptions bitwise;
  bitwise.bitwise = true;
  CompareResult r = compare_traces(a, b, bitwise);
  CHECK_FALSE(r.same());
  CHECK(r.datasets.front().path == "servo/fingers/thumb/force");
  CHECK(r.datasets.front().max_abs_error == 0.0);   // equal values, different bits

  // NaN against a number is a difference in both modes, with an infinite error.
  const auto [c, d] = twins("nan");
  set_element(d, "/haptic/fingers/thumb/depth", 1, 0, std::numeric_limits<double>::quiet_NaN());
  CompareOptions huge;
  huge.tolerance.atol = 1e300;
  r = compare_traces(c, d, huge);
  REQUIRE(r.differing_datasets() == 1);
  CHECK(std::isinf(r.datasets.front().max_abs_error));
  CHECK(r.datasets.front().first->tick == 2);
}

TEST_CASE("root attributes that differ are notes unless asked", "[compare]") {
  const std::string a = tmp_path("attr_a.h5"), b = tmp_path("attr_b.h5");
  make_trace(a, Spec{});
  Spec other;
  other.version = "v2-dirty";
  make_trace(b, other);
  CompareResult r = compare_traces(a, b);
  CHECK(r.same());
  REQUIRE(r.attributes.size() == 1);
  CHECK(r.attributes[0].name == "graspsim_version");
  CHECK(*r.attributes[0].a == "v1");
  CHECK(*r.attributes[0].b == "v2-dirty");
  CHECK_FALSE(r.attributes[0].counted);
  CompareOptions o;
  o.attributes = true;
  r = compare_traces(a, b, o);
  CHECK_FALSE(r.same());
  CHECK(r.counted_attributes() == 1);
}

TEST_CASE("unusable input is a CompareInputError naming the file and the dataset", "[compare][bad_input]") {
  const std::string good = tmp_path("good.h5");
  make_trace(good, Spec{});

  SECTION("missing file") {
    CHECK_THAT(input_error(good, tmp_path("nowhere.h5")), Catch::Contains("nowhere.h5") && Catch::Contains("no such file"));
  }
  SECTION("not HDF5") {
    const std::string text = tmp_path("text.h5");
    std::ofstream(text) << "not a trace\n";
    CHECK_THAT(input_error(text, good), Catch::Contains("text.h5") && Catch::Contains("not an HDF5 file"));
  }
  SECTION("truncated") {
    const std::string cut = tmp_path("cut.h5");
    std::filesystem::copy_file(good, cut);
    std::filesystem::resize_file(cut, std::filesystem::file_size(good) / 2);
    CHECK_THAT(input_error(good, cut), Catch::Contains("cut.h5"));
  }
  SECTION("not a graspsim trace") {
    const std::string foreign = tmp_path("foreign.h5");
    Spec s;
    s.with_schema = false;
    make_trace(foreign, s);
    CHECK_THAT(input_error(good, foreign), Catch::Contains("foreign.h5") && Catch::Contains("not a graspsim trace") && Catch::Contains("schema_version"));
  }
  SECTION("schema versions differ") {
    const std::string v2 = tmp_path("v2.h5");
    Spec s;
    s.schema_version = 2;
    make_trace(v2, s);
    CHECK_THAT(input_error(good, v2), Catch::Contains("schema versions") && Catch::Contains("has 1") && Catch::Contains("has 2"));
  }
  SECTION("rates differ") {
    const std::string fast = tmp_path("fast.h5");
    Spec s;
    s.rate_physics = 600;
    make_trace(fast, s);
    CHECK_THAT(input_error(good, fast), Catch::Contains("different rates") && Catch::Contains("1200 / 600 / 300 Hz") && Catch::Contains("1200 / 600 / 600 Hz"));
  }
  SECTION("a dataset in one trace only") {
    const std::string extra = tmp_path("extra.h5");
    Spec s;
    s.extra_dataset = true;
    make_trace(extra, s);
    CHECK_THAT(input_error(good, extra), Catch::Contains("'/physics/objects/box/extra'") && Catch::Contains("missing in '" + good + "'"));
    CHECK_THAT(input_error(extra, good), Catch::Contains("'/physics/objects/box/extra'") && Catch::Contains("missing in '" + good + "'"));
  }
  SECTION("shapes differ") {
    const std::string wide = tmp_path("wide.h5");
    Spec s;
    s.quaternion_width = 5;
    make_trace(wide, s);
    CHECK_THAT(input_error(good, wide), Catch::Contains("'/physics/objects/box/quaternion'") && Catch::Contains("(60, 4)") && Catch::Contains("(60, 5)"));
  }
}

TEST_CASE("reading in blocks gives the same result as reading at once", "[compare]") {
  const auto [a, b] = twins("blocks");
  set_element(b, "/servo/fingers/thumb/force", 177, 2, 3.0);
  set_element(b, "/physics/objects/box/position", 59, 0, 3.0);
  CompareOptions whole, tiny;
  tiny.block_rows = 7;   // blocks that straddle every boundary
  const CompareResult r1 = compare_traces(a, b, whole), r2 = compare_traces(a, b, tiny);
  REQUIRE(r1.datasets.size() == r2.datasets.size());
  for (std::size_t i = 0; i < r1.datasets.size(); ++i) {
    CHECK(r1.datasets[i].path == r2.datasets[i].path);
    CHECK(r1.datasets[i].exceeded == r2.datasets[i].exceeded);
    CHECK(r1.datasets[i].max_abs_error == r2.datasets[i].max_abs_error);
    CHECK(r1.datasets[i].elements == r2.datasets[i].elements);
  }
  CHECK(r2.datasets[0].first->tick == 177);
  CHECK(r2.datasets[1].first->tick == 236);
}

namespace {

// A graspsim-shaped trace written in SWMR mode by a child process that is killed (_exit, no
// close) after a flush: the file stays marked open for writing, as after a SIGKILL.
void make_cut_swmr_trace(const std::string& path) {
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    // A failure is the child's exit status: 4 when SWMR writing cannot start, else 3. _exit runs
    // no destructor, so the file is never closed.
    int failure = 3;
    try {
      inspect::File f = inspect::File::create(path, inspect::File::Format::kLatest);
      for (const auto& [name, v] : {std::pair{"schema_version", 1}, std::pair{"rate_servo", 1200},
                                    std::pair{"rate_haptic", 600}, std::pair{"rate_physics", 300}})
        f.write_int_attribute("/", name, v);
      for (const std::string group : {"servo", "haptic", "physics"}) {
        f.create_group(group);
        f.create_dataset(group + "/tick", std::vector<std::int64_t>{0, 4, 8, 12}, 4);
        f.create_dataset(group + "/time", std::vector<double>{0.0, 4.0 / 1200, 8.0 / 1200, 12.0 / 1200}, 4);
      }
      failure = 4;
      f.start_swmr_write();
      failure = 3;
      f.flush();
      _exit(0);   // no close: the file keeps its "open for writing" mark
    } catch (...) {
      _exit(failure);
    }
  }
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  REQUIRE(WIFEXITED(status));
  REQUIRE(WEXITSTATUS(status) == 0);
}

}  // namespace

TEST_CASE("a SWMR trace cut by a crash is opened in SWMR read mode, with a note", "[compare]") {
  const std::string cut = tmp_path("swmr_cut.h5");
  make_cut_swmr_trace(cut);
  // A plain read-only open refuses it (the mark a killed SWMR writer leaves).
  CHECK_THROWS_AS(inspect::File::open(cut), inspect::InspectError);

  const CompareResult r = compare_traces(cut, cut);
  CHECK(r.same());
  CHECK(r.loops.size() == 3);
  CHECK(r.loops[2].matched == 4);
  REQUIRE_FALSE(r.notes.empty());
  CHECK_THAT(r.notes.front(), Catch::Contains("SWMR read mode"));
}
