// Entity groups (TraceTable::add_group, recordings/README.md "Writing"): columns repeated per
// entity stored as one member, an array of one compound element per entity, read back as the
// columns add_column would give; the row type does not grow with the entities; bad groups are
// refused before the first row; a damaged group is refused by the readers.
#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_compare.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "tests/support/library.hpp"
#include "tests/support/trace_edit.hpp"

using namespace graspsim::recordings;
using Catch::Matchers::Contains;

namespace {

std::string tmp_path(const std::string& name) { return graspsim::test::fresh_tmp_path("recordings_groups_", name); }

// A trace (schema and rates, as compare needs) of one table `t`: tick and time, then `entities`
// entities e0, e1, ... of fields p (3 float64, m), n (int32) and h (uint64); row r of entity k
// holds p = (r, k, r + k / 8), n = r - k, h = 2^63 + r * 1000 + k.
void write_grouped(const std::string& file, int entities, int rows, TraceOptions options = {}) {
  TraceWriter writer(file, options);
  writer.set_attribute("schema_version", 4);
  for (const char* rate : {"rate_servo", "rate_haptic", "rate_physics"}) writer.set_attribute(rate, 1000);
  TraceTable& t = writer.table("t");
  const std::size_t tick = t.add_column("tick", 1, DType::kInt64, "tick");
  const std::size_t time = t.add_column("time", 1, DType::kFloat64, "s");
  std::vector<std::string> names;
  for (int k = 0; k < entities; ++k) names.push_back(std::string(1, 'e').append(std::to_string(k)));
  const std::size_t first = t.add_group("things", names, {{"p", 3, DType::kFloat64, "m"},
                                                          {"n", 1, DType::kInt32, "1"},
                                                          {"h", 1, DType::kUInt64, "1"}});
  t.set_attribute("things/p", "order", "x, y, z");
  CHECK(first == 2);
  for (int r = 0; r < rows; ++r) {
    double* row = t.append_row();
    row[tick] = r;
    row[time] = r / 1000.0;
    for (int k = 0; k < entities; ++k) {
      double* e = row + first + 5 * static_cast<std::size_t>(k);
      e[0] = r, e[1] = k, e[2] = r + k / 8.0, e[3] = r - k;
      e[4] = uint64_in_row((std::uint64_t{1} << 63) + static_cast<std::uint64_t>(r) * 1000 + static_cast<std::uint64_t>(k));
    }
  }
  writer.close("complete");
}

}  // namespace

TEST_CASE("a group's columns read back as columns of their own, each entity's fields together", "[recordings][groups]") {
  const std::string file = tmp_path("round_trip.h5");
  write_grouped(file, 3, 5);
  const Table t = read_table(file, "/t");
  CHECK(t.names == std::vector<std::string>{"things/e0/h", "things/e0/n", "things/e0/p", "things/e1/h",
                                            "things/e1/n", "things/e1/p", "things/e2/h", "things/e2/n",
                                            "things/e2/p", "tick", "time"});
  const Dataset& p = t.column("things/e2/p");
  REQUIRE(p.shape == std::vector<std::size_t>{5, 3});
  CHECK(p.units == "m");
  CHECK(p.values[3 * 4 + 2] == 4 + 2 / 8.0);
  CHECK(t.column("things/e1/n").dtype == DType::kInt32);
  CHECK(t.column("things/e1/n").values[4] == 3.0);
  CHECK(t.column("things/e2/h").bits[4] == (std::uint64_t{1} << 63) + 4002);
  CHECK(read_dataset(file, "/t/things/e1/p").values == t.column("things/e1/p").values);
  CHECK(read_string_attribute(file, "/t/things/e0/p", "order") == "x, y, z");
  CHECK(read_string_attribute(file, "/t/things/e0/n", "units") == "1");
  CHECK(has_object(file, "/t/things/e1"));
  CHECK_FALSE(has_object(file, "/t/things/e3"));
  CHECK(list_datasets(file).size() == 11);

  // As stored: one member for the group, an array of 3 compound elements, named by an attribute.
  const inspect::File h5 = inspect::File::open(file);
  const inspect::DatasetInfo d = h5.dataset("/t");
  REQUIRE(d.members.size() == 3);
  CHECK(d.members[2].name == "things");
  CHECK(d.members[2].width == 3);
  REQUIRE(d.members[2].fields.size() == 3);
  CHECK(d.members[2].fields[0].name == "p");
  CHECK(h5.read_string_attribute("/t", "things") == "e0\ne1\ne2");
  CHECK(h5.read_string_attribute("/t", "things/p/units") == "m");
  CHECK(h5.read_element_row("/t", "things", 1, "p", 4) == std::vector<double>{4, 1, 4 + 1 / 8.0});

  // Compared with itself, and after one element of one entity changes, that column alone differs.
  CompareOptions bitwise;
  bitwise.bitwise = true;
  CHECK(compare_traces(file, file, bitwise).same());
  const std::string changed = tmp_path("changed.h5");
  write_grouped(changed, 3, 5);
  graspsim::test::set_element(changed, "/t/things/e1/p", 2, 1, 7.0);
  const CompareResult r = compare_traces(file, changed, bitwise);
  REQUIRE(r.differing_datasets() == 1);
  CHECK(r.datasets.front().path == "t/things/e1/p");
  CHECK(r.datasets.front().first->tick == 2);
}

TEST_CASE("a group of 1 entity or of 20000 is one member of the row", "[recordings][groups]") {
  const std::string one = tmp_path("one.h5"), many = tmp_path("many.h5");
  TraceOptions two_rows;
  two_rows.block_rows = 2;
  write_grouped(one, 1, 2, two_rows);
  write_grouped(many, 20000, 2, two_rows);   // 60,000 columns: a member each would need a 2 MB row type
  CHECK(inspect::File::open(one).dataset("/t").members.size() == 3);
  const inspect::DatasetInfo d = inspect::File::open(many).dataset("/t");
  CHECK(d.members.size() == 3);
  CHECK(d.members[2].width == 20000);
  CHECK(d.type.bytes == 16 + 20000u * (24 + 4 + 8));
  const Table t = read_table(many, "/t", {"tick", "things/e19999/h"});
  CHECK(t.column("things/e19999/h").bits[1] == (std::uint64_t{1} << 63) + 1000 + 19999);
  CHECK(read_table(many, "/t").names.size() == 2 + 3 * 20000);
}

TEST_CASE("a bad group is refused before the first row, naming it", "[recordings][groups]") {
  TraceWriter writer(tmp_path("bad.h5"));
  TraceTable& t = writer.table("t");
  t.add_column("tick", 1, DType::kInt64, "tick");
  const std::vector<TraceTable::Field> fields = {{"p", 3, DType::kFloat64, "m"}};
  CHECK_THROWS_WITH(t.add_group("g", {}, fields), Contains("a group needs an entity and a field"));
  CHECK_THROWS_WITH(t.add_group("g", {"a"}, {}), Contains("a group needs an entity and a field"));
  CHECK_THROWS_WITH(t.add_group("g", {"a", "a"}, fields), Contains("entity 'a' named twice"));
  CHECK_THROWS_WITH(t.add_group("g", {"a\nb"}, fields), Contains("cannot be a column path component"));
  CHECK_THROWS_WITH(t.add_group("g", {"a/b"}, fields), Contains("cannot be a column path component"));
  CHECK_THROWS_WITH(t.add_group("tick", {"a"}, fields), Contains("clashes with column 'tick'"));
  CHECK_THROWS_WITH(t.add_group("g", {"a"}, {{"p", 0, DType::kFloat64, "m"}}), Contains("width of at least 1"));
  t.add_group("g", {"a", "b"}, fields);
  CHECK_THROWS_WITH(t.add_column("g/a/q", 1, DType::kFloat64, "m"), Contains("clashes"));
  CHECK_THROWS_WITH(t.add_group("g", {"c"}, fields), Contains("clashes"));
  // A field's attribute is the group's; an entity's own column takes none.
  CHECK_THROWS_WITH(t.set_attribute("g/a/p", "order", "x"), Contains("no column"));
  t.set_attribute("g/p", "order", "x, y, z");
  t.append_row();
  CHECK_THROWS_WITH(t.add_group("h", {"a"}, fields), Contains("after the first row"));
  writer.close("complete");
}

TEST_CASE("a damaged group's names are refused by every reader, naming the table", "[recordings][groups]") {
  const std::string file = tmp_path("damaged.h5");
  write_grouped(file, 3, 2);
  const auto refused = [&](const std::string& names, const std::string& says) {
    inspect::File::open(file, inspect::File::Mode::kReadWrite).write_string_attribute("/t", "things", names);
    INFO(names);
    CHECK_THROWS_WITH(read_table(file, "/t"), Contains(says) && Contains("'/t'"));
    CHECK_THROWS_WITH(list_datasets(file), Contains(says));
    CHECK_THROWS_AS(compare_traces(file, file), CompareInputError);
  };
  refused("e0\ne1", "names 2");
  refused("e0\ne1\ne2\ne3", "names 4");
  refused("e0\n\ne2", "cannot name a column");
  refused("e0\ne1/x\ne2", "cannot name a column");
  refused("e0\ne0\ne2", "stored twice");
}
