// Crash safety of the writer: SWMR from the first row, attributes kept for close, a cut file
// readable by a SWMR reader, and repair_trace (the `graspsim repair` step).
#include <catch2/catch.hpp>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_repair.hpp"
#include "graspsim/recordings/trace_writer.hpp"

using namespace graspsim::recordings;

namespace {

std::string tmp_path(const std::string& name) {
  const std::string path = std::string(GRASPSIM_TEST_TMP) + "/recordings_swmr_" + name;
  std::remove(path.c_str());
  return path;
}

// Whether HDF5 opens the file read-only without SWMR (what h5dump does).
bool opens_plainly(const std::string& file) {
  try {
    (void)inspect::File::open(file);
    return true;
  } catch (const inspect::InspectError&) {
    return false;
  }
}

// A child process writes `rows` rows of table "t" (block 4), flushes after `flush_at` rows, and
// dies without closing anything (like SIGKILL: no destructor, no HDF5 shutdown).
void write_and_die(const std::string& file, int rows, int flush_at) {
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    TraceWriter writer(file, TraceOptions{4, 0});
    writer.set_attribute("schema_version", std::int64_t{2});
    TraceTable& t = writer.table("t");
    t.add_column("x", 1, DType::kFloat64, "m");
    t.add_column("h", 1, DType::kUInt64, "1");
    for (int r = 0; r < rows; ++r) {
      double* row = t.append_row();
      row[0] = r;
      row[1] = uint64_in_row(0xfedcba9876543210ull + static_cast<std::uint64_t>(r));
      if (r + 1 == flush_at) writer.flush();
    }
    _exit(0);
  }
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  REQUIRE(WIFEXITED(status));
}

}  // namespace

TEST_CASE("the writer starts SWMR at the first row and then freezes the layout", "[trace_writer][swmr]") {
  const std::string file = tmp_path("frozen.h5");
  TraceWriter writer(file, TraceOptions{4, 0});
  TraceTable& t = writer.table("t");
  t.add_column("x", 1, DType::kFloat64, "m");
  TraceTable& u = writer.table("u");
  u.add_column("y", 1, DType::kFloat64, "m");
  writer.set_attribute("early", "written at once");
  *t.append_row() = 1.0;
  CHECK_THROWS_AS(u.add_column("late", 1, DType::kFloat64, "m"), TraceError);   // other table too
  CHECK_THROWS_AS(writer.table("new"), TraceError);
  CHECK_THROWS_AS(t.set_attribute("x", "late", "no"), TraceError);
  writer.set_attribute("late", "kept for close");
  writer.set_attribute("late_number", 2.5);
  writer.set_attribute("late", "kept for close, replaced");
  *u.append_row() = 2.0;
  writer.close("complete");
  CHECK(read_string_attribute(file, "/", "early") == "written at once");
  CHECK(read_string_attribute(file, "/", "late") == "kept for close, replaced");
  CHECK(read_double_attribute(file, "/", "late_number") == 2.5);
  CHECK(read_string_attribute(file, "/", "status") == "complete");
  CHECK(opens_plainly(file));   // a closed file is no longer marked for SWMR writing
}

TEST_CASE("uint64 columns keep all 64 bits", "[trace_writer][swmr]") {
  const std::string file = tmp_path("uint64.h5");
  const std::vector<std::uint64_t> values{0, 1, 0xffffffffffffffffull, 0x7ff8000000000001ull,
                                          0xfff0000000000000ull, (1ull << 53) + 1};
  {
    TraceWriter writer(file, TraceOptions{4, 0});
    TraceTable& t = writer.table("t");
    t.add_column("h", 1, DType::kUInt64, "1");
    for (std::uint64_t v : values) *t.append_row() = uint64_in_row(v);
    writer.close("complete");
  }
  const Dataset d = read_dataset(file, "/t/h");
  CHECK(d.dtype == DType::kUInt64);
  CHECK(d.bits == values);
}

// Killed after 12 rows with a flush after 6 (blocks of 4): rows 0..9 are on disk (the first
// block at row 4, the flush 4..5, the block 6..9 when row 10 came); rows 10 and 11 are lost.
TEST_CASE("a trace cut by a crash opens for a SWMR reader with every flushed row", "[trace_writer][swmr]") {
  const std::string file = tmp_path("cut.h5");
  write_and_die(file, 12, 6);
  CHECK(read_string_attribute(file, "/", "status") == "running");
  const Dataset x = read_dataset(file, "/t/x");
  CHECK(x.values == std::vector<double>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
  const Dataset h = read_dataset(file, "/t/h");
  REQUIRE(h.bits.size() == 10);
  CHECK(h.bits[9] == 0xfedcba9876543219ull);
}

TEST_CASE("repair_trace makes a cut trace open without SWMR and keeps every row", "[trace_repair][swmr]") {
  const std::string file = tmp_path("repair.h5");
  write_and_die(file, 12, 6);
  CHECK_FALSE(opens_plainly(file));   // what h5dump runs into before the repair
  const RepairResult r = repair_trace(file);
  CHECK(r.repaired);
  CHECK(r.status_before == "running");
  CHECK(r.status_after == "cut: repaired");
  CHECK(r.servo_rows == -1);   // no /servo table in this file
  CHECK(opens_plainly(file));
  CHECK(read_string_attribute(file, "/", "status") == "cut: repaired");
  CHECK(read_dataset(file, "/t/x").values == std::vector<double>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
  // A second repair finds nothing to do and changes nothing.
  const RepairResult again = repair_trace(file);
  CHECK_FALSE(again.repaired);
  CHECK(again.status_after == "cut: repaired");
}

TEST_CASE("repair_trace leaves complete traces alone and refuses files that are not traces",
          "[trace_repair][swmr][errors]") {
  const std::string complete = tmp_path("complete.h5");
  {
    TraceWriter writer(complete);
    writer.set_attribute("schema_version", std::int64_t{2});
    writer.close("complete");
  }
  const RepairResult r = repair_trace(complete);
  CHECK_FALSE(r.repaired);
  CHECK(read_string_attribute(complete, "/", "status") == "complete");

  const std::string text = tmp_path("text.h5");
  std::ofstream(text) << "not hdf5\n";
  CHECK_THROWS_WITH(repair_trace(text), Catch::Contains(text) && Catch::Contains("not an HDF5 file"));

  const std::string foreign = tmp_path("foreign.h5");
  (void)inspect::File::create(foreign);   // an empty HDF5 file
  CHECK_THROWS_WITH(repair_trace(foreign), Catch::Contains(foreign) && Catch::Contains("not a graspsim trace"));
}
