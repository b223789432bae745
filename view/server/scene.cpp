// A trace read for the viewer: checks, the scenario's shapes, the animated columns cut to the
// ticks every table holds.
#include "view/server/scene.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_recorder.hpp"
#include "graspsim/recordings/trace_schema.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::view {
namespace {

namespace rec = recordings;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  return lines;
}

std::string root_string(const std::string& trace, const std::string& name, const std::string& fallback = "") {
  return rec::has_attribute(trace, "/", name) ? rec::read_string_attribute(trace, "/", name) : fallback;
}

// The columns the viewer reads, by path ("/physics/objects/box/position"): each table read once,
// only the columns asked for (a 1000-body /physics is one pass over its rows, not 6000).
using Loaded = std::map<std::string, rec::Dataset>;

// Column `path`, `width` values a row, at least `rows` rows (a cut schema-2 trace's columns can
// end apart; schema 3 and 4 keep a table's columns in one row).
const rec::Dataset& column(const Loaded& loaded, const std::string& trace, const std::string& path, std::size_t width,
                           std::size_t rows = 0) {
  const auto found = loaded.find(path);
  if (found == loaded.end()) throw ViewError(trace + ": no column " + path);
  const rec::Dataset& d = found->second;
  const std::size_t w = d.shape.size() == 2 ? d.shape[1] : 1;
  if (w != width || d.shape.empty())
    throw ViewError(trace + ": " + path + ": expected " + std::to_string(width) + " values per row");
  if (d.values.size() < width * rows)
    throw ViewError(trace + ": " + path + " holds " + std::to_string(d.values.size() / width) + " rows, fewer than " +
                    "its table's " + std::to_string(rows) + " ticks (a cut trace: `graspsim repair` evens its tables)");
  return d;
}

std::vector<std::int64_t> ticks(const Loaded& loaded, const std::string& trace, const std::string& table) {
  const rec::Dataset& d = column(loaded, trace, "/" + table + "/tick", 1);
  return {d.values.begin(), d.values.end()};
}

// The scenario the trace recorded, with its overrides; nullopt (and `why`) when it does not load
// here (a mesh file not found from this directory, a scenario this graspsim no longer reads).
std::optional<scripting::Scenario> recorded_scenario(const std::string& trace, std::string& why) {
  if (!rec::has_attribute(trace, "/", "scenario_source")) {
    why = "the trace holds no scenario_source";
    return std::nullopt;
  }
  scripting::LoadOptions load;
  load.sets = lines_of(root_string(trace, "overrides"));
  if (!rec::has_attribute(trace, "/", "integrator")) load.sets.insert(load.sets.begin(), "integrator=paper");
  const std::string path = root_string(trace, "scenario_path", trace);
  try {
    return scripting::Scenario::load_source(rec::read_string_attribute(trace, "/", "scenario_source"), path, load);
  } catch (const std::exception& e) {
    why = e.what();
    return std::nullopt;
  }
}

// Names below "/<table>/<group>/" among the trace's columns, sorted.
std::vector<std::string> names_under(const std::vector<std::string>& columns, const std::string& prefix) {
  std::set<std::string> names;
  for (const std::string& c : columns) {
    if (c.rfind(prefix, 0) != 0) continue;
    const std::string rest = c.substr(prefix.size());
    names.insert(rest.substr(0, rest.find('/')));
  }
  return {names.begin(), names.end()};
}

std::string cut_note(const ViewScene& s) {
  const double shown = s.physics_tick.empty() ? 0.0 : static_cast<double>(s.physics_tick.back()) / s.rate_servo;
  char span[160];
  std::snprintf(span, sizeof span, "shown up to its last tick, t = %.3f s of %.3f s", shown, s.duration);
  if (s.status == "running")
    return std::string("This trace was cut (status 'running': its run was killed, or is still writing it); ") + span + ".";
  if (s.status.rfind("cut", 0) == 0) return "This trace was cut and repaired (status '" + s.status + "'); " + span + ".";
  return "This run stopped early (status '" + s.status + "'); " + span + ".";
}

void require_trace(const std::string& trace) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(trace, ec);
  if (ec || !fs::exists(st)) throw ViewError(trace + ": no such file");
  if (!fs::is_regular_file(st)) throw ViewError(trace + ": not a regular file (a trace is a file)");
  bool is_trace = false;
  try {
    is_trace = rec::has_attribute(trace, "/", "schema_version");
  } catch (const rec::TraceError& e) {
    throw ViewError(trace + ": not a graspsim trace (" + e.what() + ")");
  }
  if (!is_trace) throw ViewError(trace + ": not a graspsim trace (no root attribute 'schema_version')");
  const std::int64_t schema = rec::read_int_attribute(trace, "/", "schema_version");
  if (schema < rec::kOldestSchemaVersion || schema > rec::kSchemaVersion)
    throw ViewError(trace + ": schema_version " + std::to_string(schema) + " is not one this graspsim reads (" +
                    std::to_string(rec::kOldestSchemaVersion) + " to " +
                    std::to_string(rec::kSchemaVersion) + ")");
  for (const char* table : {"/physics", "/haptic", "/servo"}) {
    if (rec::has_object(trace, table)) continue;
    if (rec::has_attribute(trace, "/", "record"))
      throw ViewError(trace + ": recorded with --record '" + rec::read_string_attribute(trace, "/", "record") +
                      "', without " + table + ": the viewer draws the bodies from /physics and the fingers from "
                      "/haptic and /servo, and needs all three");
    throw ViewError(trace + ": not a graspsim trace (no table " + table + ")");
  }
}

// The quantities the page draws and plots, per body and per finger.
constexpr const char* kBodyColumns[] = {"position", "quaternion", "grasp_area", "torsion", "floor_contacts",
                                        "body_contacts"};
constexpr const char* kFingerColumns[] = {"god_object", "force", "state", "surface_point", "friction_radius",
                                          "depth", "slip", "body"};
constexpr const char* kContactColumns[] = {"tick", "a", "b", "point", "force"};

// Reads the columns the page needs that the trace holds (`columns`, list_datasets'), a table at a time.
Loaded load_tables(const ViewScene& s, const std::vector<std::string>& columns) {
  using rec::schema::finger_column;
  using rec::schema::object_column;
  std::map<std::string, std::vector<std::string>> wanted;   // table -> its columns
  const auto want = [&](std::string_view table, const std::string& name) {
    std::string path = "/";   // built by appends: GCC 12 warns (-Wrestrict) on "/" + ... + "/" here
    path.append(table).append("/").append(name);
    if (std::binary_search(columns.begin(), columns.end(), path)) wanted[std::string(table)].push_back(name);
  };
  for (std::string_view table : {rec::schema::kPhysics, rec::schema::kHaptic, rec::schema::kServo}) want(table, "tick");
  for (const BodyView& b : s.bodies)
    for (const char* q : kBodyColumns) want(rec::schema::kPhysics, object_column(b.name, q));
  for (const FingerView& f : s.fingers) {
    for (const char* q : kFingerColumns) want(rec::schema::kHaptic, finger_column(f.name, q));
    want(rec::schema::kServo, finger_column(f.name, "hip"));
  }
  for (const char* q : kContactColumns) want(rec::schema::kContacts, q);
  Loaded loaded;
  for (auto& [table, names] : wanted) {
    rec::Table t = rec::read_table(s.trace, "/" + table, names);
    for (std::size_t k = 0; k < names.size(); ++k) loaded.emplace("/" + table + "/" + names[k], std::move(t.columns[k]));
  }
  return loaded;
}

void load_columns(ViewScene& s, const Loaded& loaded) {
  using rec::schema::finger_column;
  using rec::schema::object_column;
  const std::string& t = s.trace;
  const std::vector<std::int64_t> physics = ticks(loaded, t, "physics"), haptic = ticks(loaded, t, "haptic"),
                                  servo = ticks(loaded, t, "servo");
  if (physics.empty()) throw ViewError(t + ": the trace holds no /physics row yet: nothing to show");
  // The last tick every table holds (a cut trace's tables may end a flush interval apart).
  std::int64_t last = physics.back();
  if (!s.fingers.empty()) last = std::min({last, haptic.empty() ? -1 : haptic.back(), servo.empty() ? -1 : servo.back()});
  if (last < physics.front()) throw ViewError(t + ": the trace's tables hold no tick in common: nothing to show");
  const auto keep = [last](const std::vector<std::int64_t>& v) {
    return static_cast<std::size_t>(std::upper_bound(v.begin(), v.end(), last) - v.begin());
  };
  const std::size_t np = keep(physics), nh = s.fingers.empty() ? 0 : keep(haptic);
  s.physics_tick.assign(physics.begin(), physics.begin() + np);
  s.haptic_tick.assign(haptic.begin(), haptic.begin() + nh);
  for (BodyView& b : s.bodies) {
    const std::string base = "/physics/" + object_column(b.name, "");
    if (!loaded.count(base + "position"))
      throw ViewError(t + ": no column " + base + "position for body '" + b.name + "'");
    const rec::Dataset &p = column(loaded, t, base + "position", 3, np), &q = column(loaded, t, base + "quaternion", 4, np);
    b.position.assign(p.values.begin(), p.values.begin() + 3 * np);
    b.quaternion.assign(q.values.begin(), q.values.begin() + 4 * np);
  }
  // Row of /servo at each kept haptic tick (every servo tick, unless --record thinned them).
  std::vector<std::size_t> servo_row(nh);
  for (std::size_t i = 0; i < nh; ++i) {
    const auto it = std::lower_bound(servo.begin(), servo.end(), s.haptic_tick[i]);
    if (it == servo.end() || *it != s.haptic_tick[i])
      throw ViewError(t + ": /servo has no row at haptic tick " + std::to_string(s.haptic_tick[i]) +
                      (rec::has_attribute(t, "/", "record")
                           ? " (recorded with --record '" + rec::read_string_attribute(t, "/", "record") + "')"
                           : std::string()) +
                      ": the viewer draws each finger's HIP from the /servo row at every haptic tick");
    servo_row[i] = static_cast<std::size_t>(it - servo.begin());
  }
  for (FingerView& f : s.fingers) {
    const std::string h = "/haptic/" + finger_column(f.name, "");
    const std::size_t servo_rows = nh == 0 ? 0 : servo_row[nh - 1] + 1;
    const rec::Dataset &go = column(loaded, t, h + "god_object", 3, nh), &force = column(loaded, t, h + "force", 3, nh),
                       &state = column(loaded, t, h + "state", 1, nh),
                       &hip = column(loaded, t, "/servo/" + finger_column(f.name, "hip"), 3, servo_rows),
                       &surface = column(loaded, t, h + "surface_point", 3, nh),
                       &circle = column(loaded, t, h + "friction_radius", 1, nh);
    f.surface_point.assign(surface.values.begin(), surface.values.begin() + 3 * nh);
    f.friction_radius.assign(circle.values.begin(), circle.values.begin() + nh);
    f.god_object.assign(go.values.begin(), go.values.begin() + 3 * nh);
    f.force.assign(force.values.begin(), force.values.begin() + 3 * nh);
    for (std::size_t i = 0; i < nh; ++i) f.state.push_back(static_cast<std::int8_t>(state.values[i]));
    for (std::size_t i = 0; i < nh; ++i)
      for (int k = 0; k < 3; ++k) f.hip.push_back(hip.values[3 * servo_row[i] + k]);
  }
}

// The columns the time series and the grasp axis read: the first `rows` values of `path`, or
// zeros where an older trace lacks it.
std::vector<double> plot_column(const ViewScene& s, const Loaded& loaded, const std::string& path, std::size_t rows) {
  if (!loaded.count(path)) return std::vector<double>(rows, 0.0);
  const rec::Dataset& d = column(loaded, s.trace, path, 1, rows);
  return {d.values.begin(), d.values.begin() + static_cast<std::ptrdiff_t>(rows)};
}

void load_plot_columns(ViewScene& s, const Loaded& loaded) {
  const std::size_t np = s.physics_tick.size(), nh = s.haptic_tick.size();
  for (BodyView& b : s.bodies) {
    const std::string base = "/physics/" + rec::schema::object_column(b.name, "");
    b.grasp_area = plot_column(s, loaded, base + "grasp_area", np);
    b.torsion = plot_column(s, loaded, base + "torsion", np);
    b.floor_contacts = plot_column(s, loaded, base + "floor_contacts", np);
    b.body_contacts = plot_column(s, loaded, base + "body_contacts", np);
  }
  for (FingerView& f : s.fingers) {
    const std::string h = "/haptic/" + rec::schema::finger_column(f.name, "");
    f.depth = plot_column(s, loaded, h + "depth", nh);
    f.slip = plot_column(s, loaded, h + "slip", nh);
    f.body = plot_column(s, loaded, h + "body", nh);
  }
}

// /contacts rows up to the last kept physics tick, when the trace recorded them.
void load_contacts(ViewScene& s, const Loaded& loaded) {
  const std::string& t = s.trace;
  if (!rec::has_object(t, "/contacts")) return;
  const std::vector<std::int64_t> tick = ticks(loaded, t, "contacts");
  const std::int64_t last = s.physics_tick.empty() ? -1 : s.physics_tick.back();
  const std::size_t n = static_cast<std::size_t>(std::upper_bound(tick.begin(), tick.end(), last) - tick.begin());
  const auto first = [n](const rec::Dataset& d, std::size_t width) {
    return std::vector<double>(d.values.begin(), d.values.begin() + static_cast<std::ptrdiff_t>(width * n));
  };
  s.contacts = true;
  s.contact_tick.assign(tick.begin(), tick.begin() + static_cast<std::ptrdiff_t>(n));
  s.contact_a = first(column(loaded, t, "/contacts/a", 1, n), 1);
  s.contact_b = first(column(loaded, t, "/contacts/b", 1, n), 1);
  s.contact_point = first(column(loaded, t, "/contacts/point", 3, n), 3);
  s.contact_force = first(column(loaded, t, "/contacts/force", 3, n), 3);
}

}  // namespace

void add_model(const Model& m, ViewScene& s) {
  s.floor = m.floor.enabled;
  s.floor_height = m.floor.height;
  for (const BodyParams& b : m.bodies) {
    BodyView& v = s.bodies.emplace_back();
    v.name = b.name;
    v.shape_known = true;
    v.shape = b.shape;
  }
  for (const FingerParams& f : m.fingers) {
    FingerView& v = s.fingers.emplace_back();
    v.name = f.name;
    v.radius = f.radius;
  }
}

ViewScene load_scene(const std::string& trace) {
  require_trace(trace);
  ViewScene s;
  try {
    s.trace = trace;
    s.status = root_string(trace, "status", "?");
    s.rate_servo = static_cast<int>(rec::read_int_attribute(trace, "/", "rate_servo"));
    s.rate_haptic = static_cast<int>(rec::read_int_attribute(trace, "/", "rate_haptic"));
    s.rate_physics = static_cast<int>(rec::read_int_attribute(trace, "/", "rate_physics"));
    if (s.rate_servo <= 0) throw ViewError(trace + ": root attribute rate_servo is not positive");
    s.duration = rec::has_attribute(trace, "/", "duration") ? rec::read_double_attribute(trace, "/", "duration") : 0.0;
    s.scenario_name = root_string(trace, "scenario_name", "?");
    const std::vector<std::string> columns = rec::list_datasets(trace);
    std::string why;
    const std::optional<scripting::Scenario> scenario = recorded_scenario(trace, why);
    if (scenario) {
      add_model(scenario->model(), s);
    } else {
      // Names from the columns, shapes unknown: the page draws placeholders and says why.
      s.floor = true;
      for (const std::string& b : names_under(columns, "/physics/objects/")) s.bodies.emplace_back().name = b;
      for (const std::string& f : names_under(columns, "/haptic/fingers/")) s.fingers.emplace_back().name = f;
    }
    const Loaded loaded = load_tables(s, columns);
    load_columns(s, loaded);
    load_plot_columns(s, loaded);
    load_contacts(s, loaded);
    if (s.status != "complete") s.note = cut_note(s);
    if (!scenario)
      s.note += (s.note.empty() ? "" : " ") + std::string("The recorded scenario does not load here (") + why +
                "): bodies are drawn as grey placeholder cubes and the floor at z = 0.";
  } catch (const rec::TraceError& e) {
    throw ViewError(trace + ": cannot be read as a graspsim trace: " + e.what());
  }
  return s;
}

}  // namespace graspsim::view
