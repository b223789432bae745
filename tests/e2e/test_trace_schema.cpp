// The schema document matches what is written: every column (a member of a table's compound
// rows) and attribute of a real trace is in recordings/README.md's tables (same shape, dtype,
// units, type), and everything the tables list is in the trace; and the README's /servo,
// /haptic and /physics columns are exactly the recorder's field tables (trace_schema.hpp).
// Parses the README; fails when they disagree, naming the difference.
#include <catch2/catch.hpp>

#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "app/run.hpp"
#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_schema.hpp"
#include "graspsim/scripting/scenario.hpp"

using namespace graspsim;

namespace {

const std::string kReadme = std::string(GRASPSIM_SOURCE_DIR) + "/recordings/README.md";
const std::string kScenario = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/two_finger_lift.lua";
const std::string kTmp = GRASPSIM_TEST_TMP;

using DatasetRow = std::tuple<std::string, std::string, std::string, std::string>;   // path, shape, dtype, units
using AttributeRow = std::tuple<std::string, std::string, std::string>;              // on, name, type

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t") + 1 - a);
}

// The cells of a markdown table row "| a | b |" (outer pipes dropped).
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line.substr(1));
  std::string cell;
  while (std::getline(in, cell, '|')) out.push_back(trim(cell));
  return out;
}

// The text between the first pair of backticks ("`/servo` (every tick)" -> "/servo").
std::string code(const std::string& cell) {
  const auto a = cell.find('`');
  if (a == std::string::npos) return cell;
  const auto b = cell.find('`', a + 1);
  return cell.substr(a + 1, b - a - 1);
}

// The rows of the table whose header starts with `header`.
std::vector<std::vector<std::string>> table(const std::string& header) {
  std::ifstream in(kReadme);
  REQUIRE(in);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!inside) {
      inside = line.rfind(header, 0) == 0;
      continue;
    }
    if (line.rfind("|", 0) != 0) break;
    if (line.rfind("|---", 0) == 0) continue;
    rows.push_back(cells(line));
  }
  REQUIRE(!rows.empty());
  return rows;
}

// A file path with finger and object names replaced by the README's placeholders.
std::string generic(const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream in(path);
  std::string part;
  while (std::getline(in, part, '/')) parts.push_back(part);
  std::string out;
  for (std::size_t i = 1; i < parts.size(); ++i) {
    std::string p = parts[i];
    if (i >= 2 && parts[i - 1] == "fingers") p = "<finger>";
    if (i >= 2 && parts[i - 1] == "objects") p = "<object>";
    if (i == 2 && parts[1] == "devices") p = "<finger>";
    out += "/" + p;
  }
  return out.empty() ? "/" : out;
}

namespace inspect = recordings::inspect;

std::string type_name(const inspect::Type& type) {
  const std::string bits = std::to_string(8 * type.bytes);
  switch (type.type_class) {
    case inspect::TypeClass::kString: return "string";
    case inspect::TypeClass::kFloat: return "float" + bits;
    case inspect::TypeClass::kInteger: return (type.is_signed ? "int" : "uint") + bits;
    default: return "?";
  }
}

struct Found {
  std::set<DatasetRow> datasets;
  std::set<AttributeRow> attributes;
  std::vector<std::string> units_missing;   // datasets without a units attribute
};

// The entity names of group `member` of table `path`: its attribute of that name, one a line.
std::vector<std::string> entities(const inspect::File& h5, const std::string& path, const std::string& member) {
  std::vector<std::string> names;
  std::stringstream in(h5.read_string_attribute(path, member));
  for (std::string line; std::getline(in, line);) names.push_back(line);
  return names;
}

// A column of the table at `path`: its row (path, shape, dtype, units); a missing units attribute
// is noted.
void add_column(Found& f, const inspect::File& h5, const std::string& path, const std::string& column,
                const inspect::Member& m, const std::string& units_key) {
  const bool array = m.type.type_class == inspect::TypeClass::kArray;
  const std::string shape = array ? "(n," + std::to_string(m.width) + ")" : "(n)";
  std::string units = "(none)";
  if (h5.has_attribute(path, units_key)) units = h5.read_string_attribute(path, units_key);
  else f.units_missing.push_back(path + "/" + column);
  f.datasets.insert({generic(path + "/" + column), shape, type_name(m.element), units});
}

// Every object of the file, read through the schema-free view (not the trace reader). A table is
// one compound dataset of shape (n); each member is a column, an array member of width w a column
// of shape (n,w); its units are attribute "<member>/units". A member that is an array of compound
// elements is a group of entities (schema 4): the table's attribute of its name lists them, and
// field f of entity e is column "<member>/<e>/<f>", its attributes "<member>/<f>/<name>". An
// attribute of a table dataset named "<column>/<name>" belongs to that column; "units" of every
// column is listed once, as "every column".
Found visit(const std::string& file) {
  Found f;
  const inspect::File h5 = inspect::File::open(file);
  for (const inspect::Object& object : h5.objects()) {
    const std::string& path = object.path;
    const bool is_dataset = object.kind == inspect::ObjectKind::kDataset;
    std::set<std::string> groups;
    if (is_dataset) {
      const inspect::DatasetInfo d = h5.dataset(path);
      const bool compound = d.type.type_class == inspect::TypeClass::kCompound;
      if (d.dims.size() != 1 || !compound) f.datasets.insert({generic(path), "not a table", "?", "?"});
      for (const inspect::Member& m : d.members) {
        if (m.fields.empty()) {
          add_column(f, h5, path, m.name, m, m.name + "/units");
          continue;
        }
        groups.insert(m.name);
        const std::vector<std::string> names = entities(h5, path, m.name);
        CHECK(names.size() == m.width);
        for (const std::string& e : names)
          for (const inspect::Member& field : m.fields)
            add_column(f, h5, path, m.name + "/" + e + "/" + field.name, field, m.name + "/" + field.name + "/units");
      }
    }
    for (const inspect::Attribute& a : h5.attributes(path)) {
      const auto slash = a.name.rfind('/');
      const auto first = a.name.find('/');
      if (is_dataset && slash != std::string::npos) {
        // A group's field attribute names the field's column of every entity.
        std::string column = path + "/" + a.name.substr(0, slash);
        if (groups.count(a.name.substr(0, first))) column = path + "/" + a.name.substr(0, first) + "/<entity>" + a.name.substr(first, slash - first);
        const std::string key = a.name.substr(slash + 1);
        if (key == "units") f.attributes.insert({"every column", "units", type_name(a.type)});
        else f.attributes.insert({generic(column), key, type_name(a.type)});
      } else {
        f.attributes.insert({generic(path), a.name, type_name(a.type)});
      }
    }
  }
  return f;
}

template <typename T>
std::string list(const std::set<T>& rows) {
  std::ostringstream out;
  for (const T& r : rows) {
    std::apply([&out](const auto&... x) { ((out << x << " | "), ...); }, r);
    out << "\n";
  }
  return out.str();
}

template <typename T>
std::set<T> minus(const std::set<T>& a, const std::set<T>& b) {
  std::set<T> out;
  for (const T& x : a)
    if (!b.count(x)) out.insert(x);
  return out;
}

}  // namespace

TEST_CASE("recordings/README.md documents exactly the datasets and attributes of a real trace",
          "[e2e][trace][schema]") {
  // A real trace of the two-finger lift (4 s, 0.3 s of wall time), with an override.
  scripting::LoadOptions load;
  load.sets.push_back("mu=0.8");
  const auto scenario = scripting::Scenario::load(kScenario, load);
  app::RunOptions options;
  options.out = kTmp + "/e2e_schema.h5";
  options.overrides = load.sets;
  options.devices.record = {false, true};   // the index finger's samples in /devices/index
  // And /contacts, which a run records only when asked (the box starts on the floor: it has rows).
  options.trace.record = recordings::RecordSelection::parse("servo,haptic,physics,devices,contacts");
  const app::RunResult result = app::run_scenario(scenario, options);
  REQUIRE(result.error.empty());

  // The README's tables.
  std::set<DatasetRow> documented;
  std::string group;
  for (const auto& row : table("| table | column |")) {
    REQUIRE(row.size() >= 5);
    if (!row[0].empty()) group = code(row[0]);
    documented.insert({group + "/" + code(row[1]), row[2], row[3], row[4]});
  }
  std::set<AttributeRow> documented_attributes;
  for (const auto& row : table("| on | attribute |")) {
    REQUIRE(row.size() >= 3);
    const std::string on = row[0].find('`') == std::string::npos ? row[0] : code(row[0]);
    // The jitter's attributes are written by jittered runs only (test_jitter_cli.cpp reads them).
    if (row.size() >= 4 && (row[3].find("only in a run with `--jitter") != std::string::npos ||
                            row[3].find("only with `jitter_amplitude`") != std::string::npos)) continue;
    documented_attributes.insert({on, code(row[1]), row[2]});
  }

  // The file's datasets and attributes, every object visited.
  const Found found = visit(options.out);

  INFO("in the trace, not in the README (path | shape | dtype | units):\n" << list(minus(found.datasets, documented)));
  INFO("in the README, not in the trace:\n" << list(minus(documented, found.datasets)));
  CHECK(found.datasets == documented);
  CHECK(found.units_missing.empty());
  INFO("attributes in the trace, not in the README (on | name | type):\n"
       << list(minus(found.attributes, documented_attributes)));
  INFO("attributes in the README, not in the trace:\n" << list(minus(documented_attributes, found.attributes)));
  CHECK(found.attributes == documented_attributes);
  // The table's schema_version is the file's.
  CHECK(documented_attributes.count({"/", "schema_version", "int64"}) == 1);
}

// The field tables TraceRecorder and DeviceRecorder declare their columns from
// (trace_schema.hpp) are what the README documents: the same columns of /servo, /haptic,
// /physics and /devices/<finger> with the same shape, dtype and units, and each column's note
// (order, values, hash) in the attribute table.
TEST_CASE("recordings/README.md documents exactly the recorders' field tables", "[e2e][trace][schema]") {
  std::set<DatasetRow> documented;
  std::string group;
  for (const auto& row : table("| table | column |")) {
    REQUIRE(row.size() >= 5);
    if (!row[0].empty()) group = code(row[0]);
    documented.insert({group + "/" + code(row[1]), row[2], row[3], row[4]});
  }
  std::set<AttributeRow> documented_notes;
  for (const auto& row : table("| on | attribute |")) {
    REQUIRE(row.size() >= 3);
    const std::string on = code(row[0]);
    // Column notes: attributes on a column path (the table attributes of /devices/<finger>,
    // device, mapping and max_force, are the runner's).
    if (on.rfind("/servo/", 0) == 0 || on.rfind("/haptic/", 0) == 0 || on.rfind("/physics/", 0) == 0 ||
        on.rfind("/contacts/", 0) == 0 || (on.rfind("/devices/<finger>/", 0) == 0))
      documented_notes.insert({on, code(row[1]), row[2]});
  }

  std::set<DatasetRow> tabled;
  std::set<AttributeRow> tabled_notes;
  for (const recordings::schema::ColumnDoc& c : recordings::schema::recorded_columns()) {
    const std::string shape = c.width == 1 ? "(n)" : "(n," + std::to_string(c.width) + ")";
    tabled.insert({c.path, shape, recordings::name_of(c.dtype), c.units});
    if (!c.note.name.empty()) tabled_notes.insert({c.path, std::string(c.note.name), "string"});
  }
  // 2 + 4 + 2 + 8 + 3 + 11 + 7 + 10 columns: tick and time in each loop, the state hash, the
  // per-finger and per-object fields, /contacts' tick, time and 5 fields, and a device's 8
  // fields and 2 counters.
  CHECK(tabled.size() == 47);

  INFO("in the field tables, not in the README (path | shape | dtype | units):\n" << list(minus(tabled, documented)));
  INFO("in the README, not in the field tables:\n" << list(minus(documented, tabled)));
  CHECK(tabled == documented);
  INFO("notes in the field tables, not in the README (on | name | type):\n" << list(minus(tabled_notes, documented_notes)));
  INFO("notes in the README, not in the field tables:\n" << list(minus(documented_notes, tabled_notes)));
  CHECK(tabled_notes == documented_notes);
}
