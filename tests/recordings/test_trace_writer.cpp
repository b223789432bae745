// Tests of TraceWriter/TraceTable and the read helpers: round trips, shapes, dtypes, status,
// errors, and that HDF5 never prints to stderr.
#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "tests/support/library.hpp"

using namespace graspsim::recordings;

namespace {

std::string tmp_path(const std::string& name) { return graspsim::test::fresh_tmp_path("recordings_", name); }

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// Float64 test values, awkward on purpose: signed zero, subnormal, extremes, inf, NaN, and
// fractions with no short binary form.
double float_value(std::int64_t row, int component) {
  switch ((row + component) % 7) {
    case 0: return -0.0;
    case 1: return 4.9e-324 * static_cast<double>(row + 1);   // subnormal
    case 2: return std::numeric_limits<double>::max() / static_cast<double>(row + 1);
    case 3: return -std::numeric_limits<double>::infinity();
    case 4: return std::numeric_limits<double>::quiet_NaN();
    default: return static_cast<double>(row) / 3.0 - static_cast<double>(component) * 0.1;
  }
}
// Integers spanning each type's range (int64 up to the double-exact 2^53).
double int64_value(std::int64_t row) {
  return (row % 2 == 0 ? 1.0 : -1.0) * (9007199254740992.0 - static_cast<double>(row));
}
double int32_value(std::int64_t row, int component) {
  return component == 0 ? -2147483648.0 + static_cast<double>(row)
                        : 2147483647.0 - static_cast<double>(row);
}
double int8_value(std::int64_t row) { return static_cast<double>(row * 37 % 256 - 128); }

struct MixedColumns {
  std::size_t a, xyz, n, pair, s;
};

// Declares the mixed table: widths 1 and 3 (float64), 1 (int64), 2 (int32), 1 (int8).
MixedColumns declare_mixed(TraceTable& t) {
  MixedColumns c{};
  c.a = t.add_column("a", 1, DType::kFloat64, "m");
  c.xyz = t.add_column("vectors/xyz", 3, DType::kFloat64, "N");
  c.n = t.add_column("n", 1, DType::kInt64, "tick");
  c.pair = t.add_column("vectors/deep/pair", 2, DType::kInt32, "1");
  c.s = t.add_column("s", 1, DType::kInt8, "rad/s");
  return c;
}

void fill_mixed(TraceTable& t, const MixedColumns& c, std::int64_t rows) {
  for (std::int64_t r = 0; r < rows; ++r) {
    double* row = t.append_row();
    row[c.a] = float_value(r, 0);
    for (int k = 0; k < 3; ++k) row[c.xyz + static_cast<std::size_t>(k)] = float_value(r, k + 1);
    row[c.n] = int64_value(r);
    for (int k = 0; k < 2; ++k) row[c.pair + static_cast<std::size_t>(k)] = int32_value(r, k);
    row[c.s] = int8_value(r);
  }
}

// Reads back the mixed table and checks every value bit for bit, plus shapes, dtypes, units.
void check_mixed(const std::string& file, const std::string& group, std::int64_t rows) {
  const auto n = static_cast<std::size_t>(rows);
  const Dataset a = read_dataset(file, group + "/a");
  CHECK(a.shape == std::vector<std::size_t>{n});
  CHECK(a.dtype == DType::kFloat64);
  CHECK(a.units == "m");
  const Dataset xyz = read_dataset(file, group + "/vectors/xyz");
  CHECK(xyz.shape == std::vector<std::size_t>{n, 3});
  CHECK(xyz.dtype == DType::kFloat64);
  CHECK(xyz.units == "N");
  const Dataset ints = read_dataset(file, group + "/n");
  CHECK(ints.shape == std::vector<std::size_t>{n});
  CHECK(ints.dtype == DType::kInt64);
  CHECK(ints.units == "tick");
  const Dataset pair = read_dataset(file, group + "/vectors/deep/pair");
  CHECK(pair.shape == std::vector<std::size_t>{n, 2});
  CHECK(pair.dtype == DType::kInt32);
  CHECK(pair.units == "1");
  const Dataset s = read_dataset(file, group + "/s");
  CHECK(s.shape == std::vector<std::size_t>{n});
  CHECK(s.dtype == DType::kInt8);
  CHECK(s.units == "rad/s");
  REQUIRE(a.values.size() == n);
  REQUIRE(xyz.values.size() == 3 * n);
  REQUIRE(ints.values.size() == n);
  REQUIRE(pair.values.size() == 2 * n);
  REQUIRE(s.values.size() == n);
  int mismatches = 0;
  for (std::int64_t r = 0; r < rows; ++r) {
    const auto i = static_cast<std::size_t>(r);
    mismatches += bits(a.values[i]) != bits(float_value(r, 0));
    for (int k = 0; k < 3; ++k) {
      mismatches += bits(xyz.values[3 * i + static_cast<std::size_t>(k)]) !=
                    bits(float_value(r, k + 1));
    }
    mismatches += ints.values[i] != int64_value(r);
    for (int k = 0; k < 2; ++k) {
      mismatches += pair.values[2 * i + static_cast<std::size_t>(k)] != int32_value(r, k);
    }
    mismatches += s.values[i] != int8_value(r);
  }
  CHECK(mismatches == 0);
}

// Chunk dimensions and deflate level of the table dataset that holds column `path` (schema 3:
// "/t/x" is member "x" of dataset "/t"), read through the schema-free HDF5 view, not the
// trace reader.
struct Layout {
  std::vector<std::uint64_t> chunk;
  std::vector<std::uint64_t> max_dims;
  int deflate = 0;   // 0 = no deflate filter
};
Layout layout_of(const std::string& file, const std::string& path) {
  const inspect::DatasetInfo d = inspect::File::open(file).dataset(path.substr(0, path.find('/', 1)));
  REQUIRE(d.chunked);
  Layout out{d.chunk, d.max_dims, 0};
  for (const inspect::Filter& f : d.filters)
    if (f.id == inspect::kFilterDeflate) out.deflate = f.values.empty() ? 0 : static_cast<int>(f.values[0]);
  return out;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

// 4 rows per block, 14 rows = 3 full blocks + a partial one of 2: every value must come back
// bit for bit (NaN, -0, subnormals, 2^53, int32/int8 extremes), with the declared dtype,
// shape (n,) for width 1 or (n, width), and its units attribute.
TEST_CASE("a table round-trips mixed dtypes and widths through full and partial blocks",
          "[trace_writer]") {
  const std::string file = tmp_path("roundtrip.h5");
  {
    TraceWriter writer(file, TraceOptions{4, 0});
    TraceTable& t = writer.table("mixed");
    const MixedColumns c = declare_mixed(t);
    CHECK(c.a == 0);
    CHECK(c.xyz == 1);
    CHECK(c.n == 4);
    CHECK(c.pair == 5);
    CHECK(c.s == 7);
    CHECK(t.row_width() == 8);
    fill_mixed(t, c, 14);
    CHECK(t.rows() == 14);
    writer.close("complete");
  }
  check_mixed(file, "/mixed", 14);
}

// Rows reach the file a block at a time: nothing before a block is full, the whole block when
// the next row is started, and the rest on flush().
TEST_CASE("rows are written block by block and on flush", "[trace_writer]") {
  const std::string file = tmp_path("blocks.h5");
  TraceWriter writer(file, TraceOptions{4, 0});
  TraceTable& t = writer.table("/t");
  t.add_column("x", 1, DType::kFloat64, "m");
  auto rows_on_disk = [&] { return read_dataset(file, "/t/x").shape.at(0); };
  for (int r = 0; r < 4; ++r) *t.append_row() = r;
  CHECK(rows_on_disk() == 0);
  *t.append_row() = 4;
  CHECK(rows_on_disk() == 4);
  t.flush();
  CHECK(rows_on_disk() == 5);
  t.flush();   // nothing buffered: no-op
  CHECK(rows_on_disk() == 5);
  CHECK(read_dataset(file, "/t/x").values == std::vector<double>{0, 1, 2, 3, 4});
  writer.close("complete");
}

// A table is one dataset of compound rows, chunked by block_rows rows, unlimited.
TEST_CASE("datasets are chunked by block_rows and unlimited along rows", "[trace_writer]") {
  const std::string file = tmp_path("chunks.h5");
  {
    TraceWriter writer(file, TraceOptions{16, 0});
    TraceTable& t = writer.table("t");
    t.add_column("one", 1, DType::kInt8, "1");
    t.add_column("four", 4, DType::kFloat64, "1");
    writer.close("complete");
  }
  const Layout one = layout_of(file, "/t/one");
  CHECK(one.chunk == std::vector<std::uint64_t>{16});
  CHECK(one.max_dims == std::vector<std::uint64_t>{inspect::kUnlimited});
  CHECK(one.deflate == 0);
  CHECK(read_dataset(file, "/t/four").shape == std::vector<std::size_t>{0, 4});
}

// TraceWriter::table(group, block_rows) gives that table its own block and chunk (the runner
// sizes each table to one flush interval of its loop); 0 keeps TraceOptions::block_rows. The
// block is written when it is full: after 5 rows of a 5-row table, not before.
TEST_CASE("a table's own block_rows sets its chunk and when its block is written",
          "[trace_writer]") {
  const std::string file = tmp_path("table_chunks.h5");
  {
    TraceWriter writer(file, TraceOptions{16, 0});
    TraceTable& a = writer.table("a", 5);
    TraceTable& b = writer.table("b");
    a.add_column("x", 3, DType::kFloat64, "m");
    b.add_column("x", 1, DType::kFloat64, "m");
    CHECK(&writer.table("a", 7) == &a);   // an existing table keeps its block
    for (int r = 0; r < 5; ++r) {
      double* row = a.append_row();
      row[0] = r, row[1] = r + 0.5, row[2] = -r;
    }
    CHECK(read_dataset(file, "/a/x").shape.at(0) == 0);
    a.append_row()[0] = 5;   // the sixth row writes the full block of five
    a.append_row()[0] = 6;
    CHECK(read_dataset(file, "/a/x").shape.at(0) == 5);
    writer.close("complete");
  }
  CHECK(layout_of(file, "/a/x").chunk == std::vector<std::uint64_t>{5});
  CHECK(layout_of(file, "/b/x").chunk == std::vector<std::uint64_t>{16});
  const Dataset a = read_dataset(file, "/a/x");
  REQUIRE(a.shape == std::vector<std::size_t>{7, 3});
  for (int r = 0; r < 5; ++r) {
    CHECK(a.values[3 * r] == r);
    CHECK(a.values[3 * r + 1] == r + 0.5);
    CHECK(a.values[3 * r + 2] == -r);
  }
  CHECK(a.values[15] == 5);
  CHECK(a.values[18] == 6);
}

// A run that records nothing still has every declared dataset, with 0 rows and its units.
TEST_CASE("a table with zero rows still has its datasets, with shape (0, ...)",
          "[trace_writer]") {
  const std::string file = tmp_path("zero_rows.h5");
  {
    TraceWriter writer(file);
    TraceTable& t = writer.table("empty");
    t.add_column("scalar", 1, DType::kInt64, "tick");
    t.add_column("nested/vec", 3, DType::kFloat64, "m");
    writer.flush();
    CHECK(t.rows() == 0);
    writer.close("complete");
  }
  const Dataset scalar = read_dataset(file, "/empty/scalar");
  CHECK(scalar.shape == std::vector<std::size_t>{0});
  CHECK(scalar.values.empty());
  CHECK(scalar.dtype == DType::kInt64);
  CHECK(scalar.units == "tick");
  const Dataset vec = read_dataset(file, "/empty/nested/vec");
  CHECK(vec.shape == std::vector<std::size_t>{0, 3});
  CHECK(vec.units == "m");
}

// Columns are fixed once rows exist (a late column would be shorter than its table); bad
// declarations are refused too, each with a TraceError naming file and dataset.
TEST_CASE("add_column after the first row, twice, or with a bad path or width throws",
          "[trace_writer]") {
  const std::string file = tmp_path("add_column.h5");
  TraceWriter writer(file);
  TraceTable& t = writer.table("t");
  t.add_column("x", 1, DType::kFloat64, "m");
  CHECK_THROWS_AS(t.add_column("x", 1, DType::kFloat64, "m"), TraceError);
  CHECK_THROWS_AS(t.add_column("/abs", 1, DType::kFloat64, "m"), TraceError);
  CHECK_THROWS_AS(t.add_column("a//b", 1, DType::kFloat64, "m"), TraceError);
  CHECK_THROWS_AS(t.add_column("zero", 0, DType::kFloat64, "m"), TraceError);
  *t.append_row() = 1.0;
  try {
    t.add_column("late", 1, DType::kFloat64, "m");
    FAIL("add_column after the first row did not throw");
  } catch (const TraceError& e) {
    CHECK(contains(e.what(), file));
    CHECK(contains(e.what(), "/t/late"));
  }
  CHECK(t.row_width() == 1);
  writer.close("complete");
}

// A file that cannot be created is reported at once, naming the path.
TEST_CASE("creating a trace in a missing directory throws TraceError naming the path",
          "[trace_writer][errors]") {
  const std::string file = "/nonexistent-dir/x.h5";
  try {
    TraceWriter writer(file);
    FAIL("no exception");
  } catch (const TraceError& e) {
    CHECK(contains(e.what(), "cannot create trace '/nonexistent-dir/x.h5'"));
    CHECK(contains(e.what(), "No such file or directory"));
  }
  CHECK_THROWS_AS(TraceWriter(tmp_path("bad_options.h5"), TraceOptions{0, 0}), TraceError);
  CHECK_THROWS_AS(TraceWriter(tmp_path("bad_options.h5"), TraceOptions{8, 10}), TraceError);
}

// A writer dropped without close() (an exception unwinding the runner) still flushes its rows
// and closes a valid file, whose status says it is incomplete.
TEST_CASE("a writer destroyed without close leaves a readable file with status incomplete",
          "[trace_writer]") {
  const std::string file = tmp_path("no_close.h5");
  {
    TraceWriter writer(file, TraceOptions{4, 0});
    TraceTable& t = writer.table("t");
    t.add_column("x", 1, DType::kFloat64, "m");
    for (int r = 0; r < 6; ++r) *t.append_row() = 0.5 * r;
  }
  CHECK(read_string_attribute(file, "/", "status") ==
        "incomplete: writer destroyed without close");
  CHECK(read_dataset(file, "/t/x").values == std::vector<double>{0.0, 0.5, 1.0, 1.5, 2.0, 2.5});
}

// The status attribute tells a finished trace from one still being written or cut short:
// "running" from creation, then whatever close() is given; close() is idempotent and the writer
// refuses use afterwards.
TEST_CASE("status is running while open, and close sets it once", "[trace_writer]") {
  const std::string file = tmp_path("status.h5");
  TraceWriter writer(file);
  TraceTable& t = writer.table("t");
  t.add_column("x", 1, DType::kFloat64, "m");
  CHECK(read_string_attribute(file, "/", "status") == "running");
  writer.close("complete");
  CHECK(writer.is_closed());
  writer.close("error: second close must not overwrite");
  CHECK(read_string_attribute(file, "/", "status") == "complete");
  CHECK_THROWS_AS(t.append_row(), TraceError);
  CHECK_THROWS_AS(writer.table("t"), TraceError);
  CHECK_THROWS_AS(writer.set_attribute("late", "x"), TraceError);

  const std::string failed = tmp_path("status_error.h5");
  {
    TraceWriter w(failed);
    w.close("error: scenario.lua:12: boom");
  }
  CHECK(read_string_attribute(failed, "/", "status") == "error: scenario.lua:12: boom");
}

// A process killed mid-run (no close, no destructor) leaves a file that opens, says
// "running", and holds every block that was full before the kill: each full block is written
// with the file's metadata.
TEST_CASE("a run killed without closing leaves a readable file with its full blocks",
          "[trace_writer]") {
  const std::string file = tmp_path("killed.h5");
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    TraceWriter writer(file, TraceOptions{4, 0});
    TraceTable& t = writer.table("t");
    t.add_column("x", 1, DType::kFloat64, "m");
    t.add_column("v", 3, DType::kInt32, "1");
    for (int r = 0; r < 10; ++r) {
      double* row = t.append_row();
      row[0] = r;
      row[1] = r;
      row[2] = -r;
      row[3] = 2 * r;
    }
    _exit(0);   // like SIGKILL: no destructors, no HDF5 shutdown
  }
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  REQUIRE(WIFEXITED(status));
  CHECK(read_string_attribute(file, "/", "status") == "running");
  CHECK(read_dataset(file, "/t/x").values == std::vector<double>{0, 1, 2, 3, 4, 5, 6, 7});
  const Dataset v = read_dataset(file, "/t/v");
  CHECK(v.shape == std::vector<std::size_t>{8, 3});
  CHECK(v.values.at(3 * 7 + 2) == 14.0);
}

// Deflate changes the bytes on disk, never the values: same bit-exact round trip, the deflate
// filter at the requested level on every dataset, and a smaller file for repetitive data.
TEST_CASE("compressed traces round-trip exactly and are deflated", "[trace_writer]") {
  const std::string plain = tmp_path("plain.h5");
  const std::string packed = tmp_path("deflate.h5");
  for (const auto& [file, level] : {std::pair{plain, 0}, std::pair{packed, 6}}) {
    TraceWriter writer(file, TraceOptions{64, level});
    // Every table is declared before the first row (the layout freezes then, for SWMR).
    TraceTable& t = writer.table("mixed");
    const MixedColumns columns = declare_mixed(t);
    TraceTable& r = writer.table("repetitive");
    r.add_column("z", 3, DType::kFloat64, "m");
    fill_mixed(t, columns, 150);
    for (int i = 0; i < 4000; ++i) {
      double* row = r.append_row();
      row[0] = row[1] = row[2] = 0.25;
    }
    writer.close("complete");
  }
  check_mixed(packed, "/mixed", 150);
  CHECK(layout_of(packed, "/mixed/vectors/xyz").deflate == 6);
  CHECK(layout_of(packed, "/mixed/s").deflate == 6);
  CHECK(layout_of(plain, "/mixed/s").deflate == 0);
  std::ifstream a(plain, std::ios::binary | std::ios::ate);
  std::ifstream b(packed, std::ios::binary | std::ios::ate);
  CHECK(b.tellg() < a.tellg() / 2);
}

// Root attributes keep their type (int64, float64, UTF-8 string) and value exactly, a
// scenario's source of tens of KB included; setting one again replaces it.
TEST_CASE("root and table attributes round-trip with their types", "[trace_writer]") {
  const std::string file = tmp_path("attributes.h5");
  std::string source;
  for (int i = 0; source.size() < 80000; ++i) {
    source += "-- line " + std::to_string(i) + ": finger µ = 0.5, ∆t = 1/3000 s\n";
  }
  {
    TraceWriter writer(file);
    writer.set_attribute("schema_version", std::int64_t{1});
    writer.set_attribute("seed", 42);   // int goes to the int64 overload
    writer.set_attribute("big", std::int64_t{-9007199254740993});
    writer.set_attribute("duration", 0.1);
    writer.set_attribute("scenario_source", source);
    writer.set_attribute("scenario_name", "first");
    writer.set_attribute("scenario_name", "pinch");   // replaced
    TraceTable& t = writer.table("haptic");
    t.add_column("fingers/a/state", 1, DType::kInt8, "1");
    t.set_attribute("fingers/a/state", "values", "0 free, 1 stick, 2 slip");
    t.set_attribute(".", "bodies", "box\nball");
    t.set_attribute("fingers", "note", "a group below the table");
    CHECK_THROWS_AS(t.set_attribute("missing", "x", "y"), TraceError);
    writer.close("complete");
  }
  CHECK(read_int_attribute(file, "/", "schema_version") == 1);
  CHECK(read_int_attribute(file, "/", "seed") == 42);
  CHECK(read_int_attribute(file, "/", "big") == -9007199254740993);
  CHECK(bits(read_double_attribute(file, "/", "duration")) == bits(0.1));
  CHECK(read_string_attribute(file, "/", "scenario_source") == source);
  CHECK(read_string_attribute(file, "/", "scenario_name") == "pinch");
  CHECK(read_string_attribute(file, "/haptic/fingers/a/state", "values") ==
        "0 free, 1 stick, 2 slip");
  CHECK(read_string_attribute(file, "/haptic", "bodies") == "box\nball");
  CHECK(read_string_attribute(file, "/haptic/fingers", "note") == "a group below the table");
  CHECK_THROWS_AS(read_int_attribute(file, "/", "scenario_name"), TraceError);
  CHECK_THROWS_AS(read_string_attribute(file, "/", "nope"), TraceError);
  CHECK(has_attribute(file, "/", "seed"));
  CHECK_FALSE(has_attribute(file, "/", "nope"));
}

// table() hands out one object per group, whatever the spelling.
TEST_CASE("table returns the same object for the same group", "[trace_writer]") {
  const std::string file = tmp_path("same_table.h5");
  TraceWriter writer(file);
  TraceTable& a = writer.table("servo");
  CHECK(&writer.table("servo") == &a);
  CHECK(&writer.table("/servo") == &a);
  CHECK(&writer.table("haptic") != &a);
  CHECK_THROWS_AS(writer.table(""), TraceError);
  CHECK_THROWS_AS(writer.table("servo/inner"), TraceError);   // a table is a dataset: no nesting
  a.add_column("tick", 1, DType::kInt64, "tick");
  writer.table("haptic").add_column("tick", 1, DType::kInt64, "tick");
  writer.close("complete");
  CHECK(has_object(file, "/servo"));
  CHECK(has_object(file, "/haptic"));
  CHECK_FALSE(has_object(file, "/physics"));
  CHECK_FALSE(has_object(file, "/physics/objects/box"));
}

// list_datasets names every column of every table, nested tables (/devices/<finger>) included,
// sorted, each one a path read_dataset reads.
TEST_CASE("list_datasets lists every column read_dataset reads", "[trace_reader]") {
  const std::string file = tmp_path("list.h5");
  TraceWriter writer(file);
  writer.table("servo").add_column("tick", 1, DType::kInt64, "tick");
  writer.table("servo").add_column("fingers/thumb/hip", 3, DType::kFloat64, "m");
  writer.table("devices/thumb").add_column("force", 3, DType::kFloat64, "N");
  writer.close("complete");
  const std::vector<std::string> paths = list_datasets(file);
  CHECK(paths == std::vector<std::string>{"/devices/thumb/force", "/servo/fingers/thumb/hip", "/servo/tick"});
  for (const std::string& p : paths) CHECK_NOTHROW(read_dataset(file, p));
  const std::string text = tmp_path("list_not_hdf5.txt");
  std::ofstream(text) << "x\n";
  CHECK_THROWS_AS(list_datasets(text), TraceError);
}

// An integer column takes only integers in its type's range; anything else is a bug upstream
// and is reported with the dataset and row instead of being silently truncated or wrapped.
TEST_CASE("a non-integer or out-of-range value in an integer column throws on flush",
          "[trace_writer][errors]") {
  for (const double bad : {2.5, 128.0, -129.0, std::nan("")}) {
    const std::string file = tmp_path("bad_int.h5");
    TraceWriter writer(file);
    TraceTable& t = writer.table("t");
    t.add_column("state", 1, DType::kInt8, "1");
    *t.append_row() = 1.0;
    *t.append_row() = bad;
    try {
      t.flush();
      FAIL("no exception for " << bad);
    } catch (const TraceError& e) {
      CHECK(contains(e.what(), "/t/state"));
      CHECK(contains(e.what(), "row 1"));
    }
    CHECK_THROWS_AS(writer.close("complete"), TraceError);
    CHECK(contains(read_string_attribute(file, "/", "status"), "error: "));
  }
}

// The reader reports what is wrong and where: not HDF5, missing file, missing dataset, a group.
TEST_CASE("read helpers throw TraceError naming the file and path", "[trace_reader][errors]") {
  const std::string text = tmp_path("not_hdf5.txt");
  std::ofstream(text) << "time,x\n0,1\n";
  try {
    read_dataset(text, "/servo/time");
    FAIL("no exception");
  } catch (const TraceError& e) {
    CHECK(contains(e.what(), text));
    CHECK(contains(e.what(), "not an HDF5 file"));
  }
  CHECK_THROWS_AS(has_object(text, "/"), TraceError);
  try {
    read_dataset(tmp_path("missing.h5"), "/x");
    FAIL("no exception");
  } catch (const TraceError& e) {
    CHECK(contains(e.what(), tmp_path("missing.h5")));
  }
  const std::string file = tmp_path("reader_errors.h5");
  {
    TraceWriter writer(file);
    writer.table("t").add_column("x", 1, DType::kFloat64, "m");
    writer.close("complete");
  }
  try {
    read_dataset(file, "/t/nope");
    FAIL("no exception");
  } catch (const TraceError& e) {
    CHECK(contains(e.what(), file));
    CHECK(contains(e.what(), "/t/nope"));
  }
  CHECK_THROWS_AS(read_dataset(file, "/t"), TraceError);   // a group
}

// Every failure above goes through HDF5 with its automatic error printing off: nothing may
// reach stderr (the default HDF5 handler would print a multi-line stack).
TEST_CASE("HDF5 errors become exceptions and print nothing to stderr", "[trace_writer][errors]") {
  const std::string captured = tmp_path("stderr.txt");
  std::fflush(stderr);
  const int saved = dup(2);
  const int sink = open(captured.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  REQUIRE(saved >= 0);
  REQUIRE(sink >= 0);
  dup2(sink, 2);
  int thrown = 0;
  try { TraceWriter w("/nonexistent-dir/x.h5"); } catch (const TraceError&) { ++thrown; }
  const std::string text = tmp_path("stderr_not_hdf5.txt");
  std::ofstream(text) << "plain text\n";
  try { read_dataset(text, "/x"); } catch (const TraceError&) { ++thrown; }
  const std::string file = tmp_path("stderr_errors.h5");
  {
    TraceWriter writer(file);
    TraceTable& t = writer.table("t");
    t.add_column("x", 1, DType::kFloat64, "m");
    try { t.set_attribute("missing", "a", "b"); } catch (const TraceError&) { ++thrown; }
    writer.close("complete");
  }
  try { read_dataset(file, "/t/missing"); } catch (const TraceError&) { ++thrown; }
  try { read_int_attribute(file, "/", "missing"); } catch (const TraceError&) { ++thrown; }
  std::fflush(stderr);
  dup2(saved, 2);
  close(saved);
  close(sink);
  CHECK(thrown == 5);
  std::ifstream in(captured);
  const std::string printed((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(printed.empty());
}

// TraceOptions::background moves HDF5 writing to a writer thread that takes the blocks in the
// order they were handed over, so the file is the same as when the appending thread writes it
// itself: the same values (check_mixed), and the same bytes (the same HDF5 calls in the same
// order allocate the same addresses). 4-row blocks and uneven flushes make many hand-overs,
// partial blocks and queued flushes, with the writer at most 4 blocks behind.
TEST_CASE("a writer thread writes the same file as the appending thread",
          "[trace_writer][background]") {
  const auto write = [](const std::string& file, bool background) {
    TraceOptions options{4, 0};
    options.background = background;
    TraceWriter writer(file, options);
    TraceTable& t = writer.table("mixed");
    const MixedColumns c = declare_mixed(t);
    TraceTable& r = writer.table("other", 3);
    r.add_column("x", 2, DType::kFloat64, "m");
    for (std::int64_t n = 0; n < 300; n += 30) {
      fill_mixed(t, c, 30);
      for (int k = 0; k < 7; ++k) {
        double* row = r.append_row();
        row[0] = static_cast<double>(n + k);
        row[1] = -0.5 * static_cast<double>(n + k);
      }
      if (n % 60 == 0) writer.flush();
    }
    writer.wait();
    writer.close("complete");
  };
  const std::string inline_file = tmp_path("inline.h5");
  const std::string thread_file = tmp_path("thread.h5");
  write(inline_file, false);
  write(thread_file, true);
  std::ifstream a(inline_file, std::ios::binary), b(thread_file, std::ios::binary);
  const std::string bytes_a((std::istreambuf_iterator<char>(a)), std::istreambuf_iterator<char>());
  const std::string bytes_b((std::istreambuf_iterator<char>(b)), std::istreambuf_iterator<char>());
  CHECK(bytes_a.size() > 1000);
  CHECK(bytes_a == bytes_b);
  const Dataset x = read_dataset(thread_file, "/other/x");
  REQUIRE(x.shape == std::vector<std::size_t>{70, 2});
  CHECK(x.values.at(2 * 69 + 1) == -0.5 * (270 + 6));
}

// A failure on the writer thread (here a value that is not an int8) is not lost: the next call
// that waits for the writer rethrows it naming the column and row, and close() writes status
// "error: ...". The appending thread never blocks on a dead writer: blocks still come back.
TEST_CASE("a writer thread's failure surfaces at the next wait and in the status",
          "[trace_writer][background][errors]") {
  const std::string file = tmp_path("thread_error.h5");
  TraceOptions options{4, 0};
  options.background = true;
  TraceWriter writer(file, options);
  TraceTable& t = writer.table("t");
  t.add_column("state", 1, DType::kInt8, "1");
  *t.append_row() = 1.0;
  *t.append_row() = 300.0;   // not an int8: the writer fails on the first block
  for (int r = 0; r < 100; ++r) {
    try {
      *t.append_row() = 0.0;   // 25 more blocks: more than the 4 in the pool
    } catch (const TraceError&) {
      // a later hand-over may rethrow already: that is the point
    }
  }
  try {
    writer.wait();
    FAIL("no exception");
  } catch (const TraceError& e) {
    CHECK(contains(e.what(), "/t/state"));
    CHECK(contains(e.what(), "row 1"));
  }
  CHECK_THROWS_AS(writer.close("complete"), TraceError);
  CHECK(contains(read_string_attribute(file, "/", "status"), "error: "));
  CHECK(contains(read_string_attribute(file, "/", "status"), "row 1"));
}

// HDF5 is not thread-safe in Debian's build: readers in the same process take the module's lock,
// so reading one trace while a writer thread writes another is safe (a data race here would
// show as corrupt reads or a crash; the lock makes every read exact).
TEST_CASE("reading a trace while a writer thread writes another is safe",
          "[trace_writer][background]") {
  const std::string done = tmp_path("read_me.h5");
  {
    TraceWriter writer(done, TraceOptions{16, 0});
    TraceTable& t = writer.table("t");
    t.add_column("x", 1, DType::kFloat64, "m");
    for (int r = 0; r < 100; ++r) *t.append_row() = r;
    writer.close("complete");
  }
  const std::string file = tmp_path("being_written.h5");
  TraceOptions options{8, 0};
  options.background = true;
  TraceWriter writer(file, options);
  TraceTable& t = writer.table("t");
  t.add_column("x", 1, DType::kFloat64, "m");
  int exact = 0;
  for (int r = 0; r < 400; ++r) {
    *t.append_row() = r;
    if (r % 8 == 7) writer.flush();
    if (r % 20 == 0) exact += read_dataset(done, "/t/x").values.at(99) == 99.0;
  }
  writer.close("complete");
  CHECK(exact == 20);
  CHECK(read_dataset(file, "/t/x").values.at(399) == 399.0);
}

// Column paths form a tree (as datasets in groups did): "a" and "a/b" cannot both be columns of
// a table, in either order, since "/t/a" would then name a column and a group of columns.
TEST_CASE("a column cannot be a prefix of another", "[trace_writer][errors]") {
  const std::string file = tmp_path("prefix_columns.h5");
  TraceWriter writer(file);
  TraceTable& t = writer.table("t");
  t.add_column("a/b", 1, DType::kFloat64, "m");
  CHECK_THROWS_WITH(t.add_column("a", 1, DType::kFloat64, "m"), Catch::Contains("clashes with column 'a/b'"));
  t.add_column("c", 1, DType::kFloat64, "m");
  CHECK_THROWS_AS(t.add_column("c/d", 1, DType::kFloat64, "m"), TraceError);
  t.add_column("ab", 1, DType::kFloat64, "m");   // a prefix of the name, not of the path: fine
  double* row = t.append_row();
  row[0] = 1.0, row[1] = 2.0, row[2] = 3.0;
  writer.close("complete");
  CHECK(read_dataset(file, "/t/a/b").values == std::vector<double>{1.0});
  CHECK(read_dataset(file, "/t/ab").values == std::vector<double>{3.0});
  CHECK(has_object(file, "/t/a"));   // a group of columns
  CHECK_THROWS_AS(read_dataset(file, "/t/a"), TraceError);
}

// HDF5 keeps a dataset's datatype in one object header message (64 KiB at most): a table with
// too many columns for one compound row is refused at the first row, with the reason, before
// any simulation time is spent, not at close (where the writer thread would find it).
// 12 columns of width 3 per object, named as the recorder names them: 40 objects fit, 400 do not.
// (HDF5 itself takes up to 86 of them: the estimate is conservative by about 5%.)
TEST_CASE("a table too wide for one HDF5 row type fails at the first row", "[trace_writer][errors]") {
  for (const int objects : {40, 400}) {
    const std::string file = tmp_path("wide.h5");
    TraceOptions options;
    options.background = true;
    TraceWriter writer(file, options);
    TraceTable& t = writer.table("physics");
    for (int k = 0; k < objects; ++k) {
      const std::string p = "objects/object_" + std::to_string(k) + "/";
      for (const char* q : {"position", "quaternion", "velocity", "angular_velocity", "force", "torque",
                            "floor_contacts", "body_contacts", "grasp_area", "torsion", "twist", "extra"}) {
        t.add_column(p + q, 3, DType::kFloat64, "1");
      }
    }
    INFO(objects << " objects");
    if (objects == 40) {
      CHECK_NOTHROW(t.append_row());
      CHECK_NOTHROW(writer.close("complete"));
    } else {
      CHECK_THROWS_WITH(t.append_row(), Catch::Contains("object header"));
      CHECK_THROWS_AS(writer.close("complete"), TraceError);
    }
  }
}

// No object of a trace carries a time stamp, the root group included, so two runs of the same
// inputs write the same bytes whatever second they ran in (with them, the root group's header
// differs, and this file's background-vs-inline byte test fails about once in 40 runs).
TEST_CASE("no object of a trace carries a time stamp", "[trace_writer]") {
  const std::string file = tmp_path("untimed.h5");
  {
    TraceWriter writer(file);
    TraceTable& t = writer.table("t");
    t.add_column("x", 1, DType::kFloat64, "m");
    *t.append_row() = 1.0;
    writer.close("complete");
  }
  const inspect::File f = inspect::File::open(file);
  for (const char* path : {"/", "/t"}) {
    const inspect::ObjectTimes times = f.times(path);
    INFO(path);
    CHECK(times.change == 0);
    CHECK(times.modification == 0);
    CHECK(times.birth == 0);
  }
}
