// The scenario format and its conversion into engine and device types (see scripting/README.md).
#include "schema.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <stdexcept>

#include "mesh_file.hpp"
#include "messages.hpp"

namespace graspsim::scripting::detail {
namespace {

// ---------------------------------------------------------------------------------------------
// Where a value sits, for messages: the element ("objects[1] 'box'") and the field inside it
// ("material.mu"), printed as "objects[1] 'box': material.mu".
struct Where {
  std::string element;
  std::string field;

  Where operator/(const std::string& name) const {
    return Where{element, field.empty() ? name : field + "." + name};
  }
  Where operator[](std::size_t index) const {   // 1-based
    return Where{element, field + "[" + std::to_string(index) + "]"};
  }
  std::string str() const {
    if (element.empty()) return field;
    if (field.empty()) return element;
    return element + ": " + field;
  }
};

[[noreturn]] void fail(const Where& where, const std::string& what) {
  const std::string at = where.str();
  throw ConversionError(at.empty() ? what : at + ": " + what);
}

// ---------------------------------------------------------------------------------------------
// Reading single values.

double number(const LuaValue& value, const Where& where) {
  if (!value.is_number()) fail(where, "expected a number, got " + value.type_name());
  return value.number;
}

double finite_number(const LuaValue& value, const Where& where) {
  const double x = number(value, where);
  if (!std::isfinite(x)) fail(where, "must be finite (got " + format_short(x) + ")");
  return x;
}

std::int64_t integer(const LuaValue& value, const Where& where) {
  const double x = number(value, where);
  if (value.type == LuaValue::Type::kInteger) return value.integer;
  // An integral float (3e3) is as good as an integer; 2^63 is the first double out of range.
  if (std::floor(x) != x || !(std::abs(x) < 9223372036854775808.0)) {
    fail(where, "expected an integer, got " + format_short(x));
  }
  return static_cast<std::int64_t>(x);
}

std::string string_value(const LuaValue& value, const Where& where) {
  if (value.type != LuaValue::Type::kString) fail(where, "expected a string, got " + value.type_name());
  return value.text;
}

// The elements of an array {a, b, c}: keys exactly 1..n.
std::vector<const LuaValue*> array(const LuaValue& value, const Where& where,
                                   const std::string& shape) {
  if (!value.is_table()) fail(where, "expected " + shape + ", got " + value.type_name());
  if (value.array_length() < 0) {
    for (std::size_t i = 0; i < value.entries.size(); ++i) {
      const LuaKey& key = value.entries[i].key;
      if (!key.is_index) {
        fail(where, "expected " + shape + ", got a table with field '" + key.name + "'");
      }
      if (key.index != static_cast<std::int64_t>(i) + 1) {
        fail(where, "expected " + shape + ", but element [" + std::to_string(i + 1) +
                        "] is missing (a hole in the array)");
      }
    }
  }
  std::vector<const LuaValue*> elements;
  for (const LuaValue::Entry& entry : value.entries) elements.push_back(&entry.value);
  return elements;
}

std::vector<double> numbers(const LuaValue& value, const Where& where, std::size_t count,
                            const std::string& shape) {
  const std::string expected = shape + " (" + std::to_string(count) + " numbers)";
  if (!value.is_table()) fail(where, "expected " + expected + ", got " + value.type_name());
  const std::vector<const LuaValue*> elements = array(value, where, expected);
  if (elements.size() != count) {
    fail(where, "expected " + expected + ", got " + std::to_string(elements.size()) +
                    (elements.size() == 1 ? " element" : " elements"));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < count; ++i) out.push_back(finite_number(*elements[i], where[i + 1]));
  return out;
}

Vec3 vec3(const LuaValue& value, const Where& where) {
  const std::vector<double> v = numbers(value, where, 3, "{x, y, z}");
  return Vec3(v[0], v[1], v[2]);
}

// A unit quaternion {w, x, y, z}; within 1e-6 of unit length it is normalised.
Quat quaternion(const LuaValue& value, const Where& where) {
  const std::vector<double> v = numbers(value, where, 4, "{w, x, y, z}");
  Quat q(v[0], v[1], v[2], v[3]);
  const double norm = q.norm();
  if (!(std::abs(norm - 1.0) <= 1e-6)) {
    fail(where, "must be a unit quaternion {w, x, y, z} (its norm is " + format_short(norm) + ")");
  }
  q.normalize();
  return q;
}

bool valid_name(const std::string& name) {
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

// ---------------------------------------------------------------------------------------------
// A table of named fields, every one of them known.
class Record {
 public:
  Record(const LuaValue& table, Where where, TableKind kind) : table_(table), where_(std::move(where)) {
    if (!table.is_table()) fail(where_, "expected a table, got " + table.type_name());
    std::vector<std::string> problems;
    for (const LuaValue::Entry& entry : table.entries) {
      if (entry.key.is_index) {
        problems.push_back("unexpected array element [" + std::to_string(entry.key.index) +
                           "] (expected named fields, like { " + fields_of(kind).front() +
                           " = ... })");
      } else if (std::find(fields_of(kind).begin(), fields_of(kind).end(), entry.key.name) ==
                 fields_of(kind).end()) {
        problems.push_back("unknown field '" + entry.key.name + "'" +
                           suggest(entry.key.name, fields_of(kind), "known fields"));
      }
    }
    // Entries are sorted by key, so the problems come in a fixed order.
    if (!problems.empty()) fail(where_, join(problems, "; "));
  }

  const LuaValue* get(const std::string& name) const { return table_.find(name); }
  Where at(const std::string& name) const { return where_ / name; }
  const Where& where() const { return where_; }

  const LuaValue& required(const std::string& name, const std::string& what) const {
    const LuaValue* value = get(name);
    if (value == nullptr) fail(at(name), "missing (" + what + ")");
    return *value;
  }
  double number_or(const std::string& name, double fallback) const {
    const LuaValue* value = get(name);
    return value != nullptr ? number(*value, at(name)) : fallback;
  }
  Vec3 vec3_or(const std::string& name, const Vec3& fallback) const {
    const LuaValue* value = get(name);
    return value != nullptr ? vec3(*value, at(name)) : fallback;
  }
  std::string string_or(const std::string& name, const std::string& fallback) const {
    const LuaValue* value = get(name);
    return value != nullptr ? string_value(*value, at(name)) : fallback;
  }

 private:
  const LuaValue& table_;
  Where where_;
};

// "objects[1] 'box'", or "objects[1]" while the element has no usable name.
std::string element_label(const char* array, std::size_t index, const LuaValue& element,
                          const char* name_key) {
  std::string label = std::string(array) + "[" + std::to_string(index) + "]";
  if (element.is_table()) {
    const LuaValue* name = element.find(name_key);
    if (name != nullptr && name->type == LuaValue::Type::kString) label += " '" + name->text + "'";
  }
  return label;
}

// A choice among names, with a suggestion when it is close to one of them.
std::string choice(const LuaValue& value, const Where& where, const std::vector<std::string>& names,
                   const std::string& noun) {
  const std::string given = string_value(value, where);
  if (std::find(names.begin(), names.end(), given) == names.end()) {
    fail(where, "unknown " + noun + " '" + given + "'" + suggest(given, names, "supported " + noun + "s"));
  }
  return given;
}

// ---------------------------------------------------------------------------------------------
// The tables of the format.

Material material(const LuaValue& value, const Where& where, const Material& defaults) {
  const Record r(value, where, TableKind::kMaterial);
  Material m = defaults;
  m.mu = r.number_or("mu", m.mu);
  m.stiffness = r.number_or("stiffness", m.stiffness);
  m.damping = r.number_or("damping", m.damping);
  m.mu_kinetic = r.number_or("mu_kinetic", m.mu_kinetic);
  if (r.get("mu_kinetic") != nullptr && !(m.mu_kinetic >= 0.0)) {
    fail(r.at("mu_kinetic"), "must be >= 0 (got " + format_short(m.mu_kinetic) + ")");
  }
  m.viscous = r.number_or("viscous", m.viscous);
  return m;
}

Rates read_rates(const LuaValue* value) {
  Rates rates;
  if (value == nullptr) return rates;
  const Record r(*value, Where{"", "rates"}, TableKind::kRates);
  const auto rate = [&](const char* name, int fallback) {
    const LuaValue* v = r.get(name);
    if (v == nullptr) return fallback;
    const std::int64_t hz = integer(*v, r.at(name));
    // validate() says why a rate <= 0 is wrong; here only what does not fit an int.
    if (hz > 1'000'000'000 || hz < -1'000'000'000) {
      fail(r.at(name), "must be a positive integer number of Hz (got " + std::to_string(hz) + ")");
    }
    return static_cast<int>(hz);
  };
  rates.servo = rate("servo", rates.servo);
  rates.haptic = rate("haptic", rates.haptic);
  rates.physics = rate("physics", rates.physics);
  return rates;
}

FloorParams read_floor(const LuaValue* value) {
  FloorParams floor;
  if (value == nullptr) return floor;
  const Where where{"", "floor"};
  if (value->type == LuaValue::Type::kBoolean) {
    floor.enabled = value->boolean;
    return floor;
  }
  if (!value->is_table()) fail(where, "expected a table, true or false, got " + value->type_name());
  const Record r(*value, where, TableKind::kFloor);
  floor.enabled = true;
  floor.height = r.number_or("height", floor.height);
  if (const LuaValue* m = r.get("material")) floor.material = material(*m, r.at("material"), floor.material);
  return floor;
}

// sleep = true | false | { linear_speed = m/s, angular_speed = rad/s, time = s } (a table: on).
SleepParams read_sleep(const LuaValue* value) {
  SleepParams sleep;
  if (value == nullptr) return sleep;
  const Where where{"", "sleep"};
  if (value->type == LuaValue::Type::kBoolean) {
    sleep.enabled = value->boolean;
    return sleep;
  }
  if (!value->is_table()) fail(where, "expected a table, true or false, got " + value->type_name());
  const Record r(*value, where, TableKind::kSleep);
  sleep.enabled = true;
  sleep.linear_speed = r.number_or("linear_speed", sleep.linear_speed);
  sleep.angular_speed = r.number_or("angular_speed", sleep.angular_speed);
  sleep.time = r.number_or("time", sleep.time);
  return sleep;
}

BodyParams object(const LuaValue& value, std::size_t index, const std::string& base_dir,
                  std::vector<std::string>& files) {
  const Where where{element_label("objects", index, value, "name"), ""};
  const Record r(value, where, TableKind::kObject);
  BodyParams body;
  body.name = string_value(r.required("name", "every object needs a name"), r.at("name"));
  if (!valid_name(body.name)) {
    fail(r.at("name"), "'" + body.name + "' is not a valid name (letters, digits and _, not "
                       "starting with a digit)");
  }
  if (body.name == "floor") fail(r.at("name"), "'floor' is reserved for the floor");
  const std::string kind = r.get("shape") == nullptr ? "box"
      : choice(*r.get("shape"), r.at("shape"), {"box", "sphere", "cylinder", "capsule", "convex", "mesh"}, "shape");
  // Each kind takes its own fields and no other's.
  const std::vector<std::string> takes =
      kind == "box" ? std::vector<std::string>{"size"}
      : kind == "sphere" ? std::vector<std::string>{"radius"}
      : kind == "cylinder" || kind == "capsule" ? std::vector<std::string>{"radius", "length"}
      : std::vector<std::string>{"file", "scale"};
  for (const char* field : {"size", "radius", "length", "file", "scale"}) {
    if (r.get(field) != nullptr && std::find(takes.begin(), takes.end(), field) == takes.end()) {
      fail(r.at(field), "does not apply to shape = \"" + kind + "\" (it takes " + join(takes, " and ") + ")");
    }
  }
  const LuaValue* mass = r.get("mass");
  const LuaValue* density = r.get("density");
  if (mass != nullptr && density != nullptr) fail(where, "give either mass or density, not both");
  if (mass == nullptr && density == nullptr) fail(where, "give its mass (kg) or its density (kg/m^3)");
  double rho = 0.0;
  if (density != nullptr) {
    rho = number(*density, r.at("density"));
    if (!(rho > 0.0) || std::isinf(rho)) {
      fail(r.at("density"), "must be > 0 kg/m^3 and finite (got " + format_short(rho) + ")");
    }
  }
  // The file frame of a mesh: x_file = frame.centre + frame.rotation x_body.
  PrincipalFrame frame;
  const bool from_file = kind == "convex" || kind == "mesh";
  if (kind == "box") {
    const Vec3 size = vec3(r.required("size", "{x, y, z}: the box's full edge lengths in m"), r.at("size"));
    body.shape = box_shape(size / 2.0);
    body.mass = mass != nullptr ? number(*mass, r.at("mass")) : rho * size.x() * size.y() * size.z();
    const Vec3 solid = box_inertia(body.mass, body.shape.half_extents);
    if (r.get("inertia") == nullptr && !solid.allFinite() && std::isfinite(body.mass) &&
        body.shape.half_extents.allFinite()) {
      fail(r.at("size"), "too large: the box's moments of inertia overflow");
    }
    body.inertia = solid;
  } else {
    if (from_file) {
      const std::string name = string_value(r.required("file", "the OBJ or STL file, relative to the scenario"), r.at("file"));
      const double scale = r.number_or("scale", 1.0);
      if (!(scale > 0.0) || std::isinf(scale)) {
        fail(r.at("scale"), "must be > 0 and finite (got " + format_short(scale) + ")");
      }
      const std::filesystem::path given(name);
      const std::string path = given.is_absolute() || base_dir.empty() ? name : (std::filesystem::path(base_dir) / given).string();
      MeshFile file;
      files.push_back(path);
      try {
        file = read_mesh_file(path);
      } catch (const ConversionError& e) {
        fail(r.at("file"), e.what());
      }
      for (Vec3& v : file.mesh.vertices) v *= scale;
      try {
        // Checked in the file's frame first, so that positions in messages are the file's.
        if (kind == "convex") convex_polyhedron(file.mesh);
        TriangleMesh body_mesh = to_principal_frame(file.mesh, frame);
        body.shape = kind == "convex" ? convex_shape(std::move(body_mesh)) : mesh_shape(std::move(body_mesh));
      } catch (const MeshError& e) {
        fail(r.at("file"), mesh_location(file, path, e.triangle()) + e.what() +
                               (kind == "convex" && std::string(e.what()).find("not convex") != std::string::npos
                                    ? " (use shape = \"mesh\" for a non-convex solid)" : ""));
      }
    } else {
      const double radius = number(r.required("radius", "m"), r.at("radius"));
      if (kind == "sphere") {
        body.shape = sphere_shape(radius);
      } else {
        const double length = number(r.required("length", "m: the length of the cylinder (part), along body z"), r.at("length"));
        body.shape = kind == "cylinder" ? cylinder_shape(radius, length / 2.0) : capsule_shape(radius, length / 2.0);
      }
    }
    // Mass properties of the unit-density solid, scaled to the density or the given mass.
    const MassProperties unit = mass_properties(body.shape, 1.0);
    const Vec3 moments = from_file ? frame.moments : Vec3(unit.inertia.diagonal());
    body.mass = mass != nullptr ? number(*mass, r.at("mass")) : rho * unit.mass;
    body.inertia = moments * (body.mass / unit.mass);
  }
  body.inertia = r.vec3_or("inertia", body.inertia);
  if (const LuaValue* m = r.get("material")) body.material = material(*m, r.at("material"), Material{});
  body.position = r.vec3_or("position", body.position);
  if (const LuaValue* q = r.get("orientation")) body.orientation = quaternion(*q, r.at("orientation"));
  if (from_file) {
    // position and orientation place the file's frame; the body sits at the centre of mass,
    // along the principal axes.
    body.position += body.orientation * frame.centre;
    body.orientation = (body.orientation * Quat(frame.rotation)).normalized();
  }
  body.velocity = r.vec3_or("velocity", body.velocity);
  body.angular_velocity = r.vec3_or("angular_velocity", body.angular_velocity);
  return body;
}

struct FingerParts {
  FingerParams params;
  FingerSetup setup;
  TrajectoryParts trajectory;
};

FingerParts finger(const LuaValue& value, std::size_t index) {
  const Where where{element_label("fingers", index, value, "name"), ""};
  const Record r(value, where, TableKind::kFinger);
  FingerParts out;
  out.params.name = string_value(r.required("name", "every finger needs a name"), r.at("name"));
  if (!valid_name(out.params.name)) {
    fail(r.at("name"), "'" + out.params.name + "' is not a valid name (letters, digits and _, "
                       "not starting with a digit)");
  }
  out.params.stiffness = r.number_or("stiffness", out.params.stiffness);
  out.params.damping = r.number_or("damping", out.params.damping);
  out.params.radius = r.number_or("radius", out.params.radius);
  out.setup.limits.max_force = r.number_or("max_force", out.setup.limits.max_force);
  if (!(out.setup.limits.max_force > 0.0) || std::isinf(out.setup.limits.max_force)) {
    fail(r.at("max_force"), "must be > 0 N and finite (got " +
                                format_short(out.setup.limits.max_force) + ")");
  }
  if (const LuaValue* device = r.get("device")) {
    // The device's default spec and workspace mapping (world = offset + scale R p); the spec's
    // syntax is checked by the CLI's device factory, which knows the kinds (app/devices.cpp).
    const Record d(*device, r.at("device"), TableKind::kDevice);
    out.setup.device = d.string_or("default", out.setup.device);
    if (out.setup.device.empty()) fail(d.at("default"), "must not be empty (\"scripted\", \"sim-phantom\", ...)");
    out.setup.mapping.scale = d.number_or("scale", 1.0);
    if (!(out.setup.mapping.scale > 0.0) || std::isinf(out.setup.mapping.scale)) {
      fail(d.at("scale"), "must be > 0 and finite (m world per m device; got " +
                              format_short(out.setup.mapping.scale) + ")");
    }
    out.setup.mapping.offset = d.vec3_or("offset", out.setup.mapping.offset);
    out.setup.mapping.rotation = d.vec3_or("rotation", out.setup.mapping.rotation);
  }
  const Where at_trajectory = r.at("trajectory");
  const LuaValue& trajectory = r.required(
      "trajectory", "waypoints { {t = 0, p = {x, y, z}}, ... } or a function(t) returning x, y, z");
  const LuaValue* interpolation = r.get("interpolation");
  if (trajectory.type == LuaValue::Type::kFunction) {
    if (interpolation != nullptr) {
      fail(r.at("interpolation"), "only applies to waypoint trajectories, not to a function");
    }
    out.trajectory.function_ref = trajectory.ref;
    return out;
  }
  const std::string shape = "waypoints { {t = 0, p = {x, y, z}}, ... } or a function(t)";
  if (!trajectory.is_table()) fail(at_trajectory, "expected " + shape + ", got " + trajectory.type_name());
  const std::vector<const LuaValue*> waypoints = array(trajectory, at_trajectory, shape);
  if (waypoints.empty()) fail(at_trajectory, "needs at least one waypoint");
  bool has_pitch = false;
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    const Record w(*waypoints[i], at_trajectory[i + 1], TableKind::kWaypoint);
    hw::Waypoint waypoint;
    waypoint.time = finite_number(w.required("t", "the time in s"), w.at("t"));
    waypoint.position = vec3(w.required("p", "the position {x, y, z} in m"), w.at("p"));
    // The gimbal pitch (rad): on every waypoint or on none, so that no waypoint holds an
    // unstated angle.
    const LuaValue* pitch = w.get("pitch");
    if (i == 0) has_pitch = pitch != nullptr;
    if ((pitch != nullptr) != has_pitch) {
      fail(pitch != nullptr ? w.at("pitch") : at_trajectory[i + 1],
           std::string(has_pitch ? "has no pitch but the first waypoint has one"
                                 : "has a pitch but the first waypoint has none") +
               ": give pitch (rad) on every waypoint or on none");
    }
    if (pitch != nullptr) waypoint.pitch = finite_number(*pitch, w.at("pitch"));
    if (i > 0 && !(waypoint.time > out.trajectory.waypoints.back().time)) {
      fail(w.at("t"), format_short(waypoint.time) + " s does not come after the previous "
                      "waypoint's " + format_short(out.trajectory.waypoints.back().time) +
                      " s (times must increase strictly)");
    }
    out.trajectory.waypoints.push_back(waypoint);
  }
  if (interpolation != nullptr) {
    const std::string name = choice(*interpolation, r.at("interpolation"), {"minjerk", "linear"},
                                    "interpolation");
    out.trajectory.interpolation =
        name == "linear" ? hw::Interpolation::kLinear : hw::Interpolation::kMinimumJerk;
  }
  return out;
}

Expectation expectation(const LuaValue& value, std::size_t index, double duration) {
  const Where where{element_label("expect", index, value, "what"), ""};
  const Record r(value, where, TableKind::kExpectation);
  Expectation e;
  e.what = string_value(r.required("what", "a sentence saying what is expected"), r.at("what"));
  if (e.what.empty()) fail(r.at("what"), "must not be empty");
  if (const LuaValue* at = r.get("at")) {
    e.at = number(*at, r.at("at"));
    if (!(e.at >= 0.0 && e.at <= duration)) {
      fail(r.at("at"), "must be a time in [0, duration = " + format_short(duration) + "] s (got " +
                           format_short(e.at) + ")");
    }
  }
  const LuaValue& check =
      r.required("check", "a function(sim) returning a boolean and an optional message");
  if (check.type != LuaValue::Type::kFunction) {
    fail(r.at("check"), "expected a function(sim), got " + check.type_name());
  }
  e.function_ref = check.ref;
  return e;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The format's tables.

bool is_record(TableKind kind) { return !fields_of(kind).empty(); }

bool is_named_array(TableKind kind) {
  return kind == TableKind::kObjects || kind == TableKind::kFingers || kind == TableKind::kExpects;
}

const std::vector<std::string>& fields_of(TableKind kind) {
  static const std::vector<std::string> kRoot = {
      "name", "description", "duration", "seed", "rates", "gravity", "integrator", "implicit_order", "local_model", "stability",
      "gyroscopic", "grasp", "floor", "sleep", "objects", "fingers", "expect"};
  static const std::vector<std::string> kGrasp = {"torsion", "critical_area", "gimbal_finger", "dead_band",
                                                      "torsional_damping"};
  static const std::vector<std::string> kRates = {"servo", "haptic", "physics"};
  static const std::vector<std::string> kFloor = {"height", "material"};
  static const std::vector<std::string> kSleep = {"linear_speed", "angular_speed", "time"};
  static const std::vector<std::string> kMaterial = {"mu", "mu_kinetic", "stiffness", "damping", "viscous"};
  static const std::vector<std::string> kObject = {
      "name", "shape", "size", "radius", "length", "file", "scale", "mass", "density", "inertia",
      "position", "orientation", "velocity", "angular_velocity", "material"};
  static const std::vector<std::string> kFinger = {
      "name", "stiffness", "damping", "radius", "max_force", "trajectory", "interpolation", "device"};
  static const std::vector<std::string> kDevice = {"default", "scale", "offset", "rotation"};
  static const std::vector<std::string> kWaypoint = {"t", "p", "pitch"};
  static const std::vector<std::string> kExpectation = {"what", "at", "check"};
  static const std::vector<std::string> kNone;
  switch (kind) {
    case TableKind::kRoot: return kRoot;
    case TableKind::kRates: return kRates;
    case TableKind::kFloor: return kFloor;
    case TableKind::kSleep: return kSleep;
    case TableKind::kMaterial: return kMaterial;
    case TableKind::kGrasp: return kGrasp;
    case TableKind::kObject: return kObject;
    case TableKind::kFinger: return kFinger;
    case TableKind::kDevice: return kDevice;
    case TableKind::kWaypoint: return kWaypoint;
    case TableKind::kExpectation: return kExpectation;
    default: return kNone;
  }
}

TableKind child_kind(TableKind parent, const LuaKey& key) {
  const std::string& name = key.name;
  switch (parent) {
    case TableKind::kRoot:
      if (key.is_index) return TableKind::kValue;
      if (name == "rates") return TableKind::kRates;
      if (name == "floor") return TableKind::kFloor;
      if (name == "sleep") return TableKind::kSleep;
      if (name == "grasp") return TableKind::kGrasp;
      if (name == "gravity") return TableKind::kVector;
      if (name == "objects") return TableKind::kObjects;
      if (name == "fingers") return TableKind::kFingers;
      if (name == "expect") return TableKind::kExpects;
      return TableKind::kValue;
    case TableKind::kFloor:
      return !key.is_index && name == "material" ? TableKind::kMaterial : TableKind::kValue;
    case TableKind::kObject:
      if (key.is_index) return TableKind::kValue;
      if (name == "material") return TableKind::kMaterial;
      if (name == "size" || name == "inertia" || name == "position" || name == "orientation" ||
          name == "velocity" || name == "angular_velocity") {
        return TableKind::kVector;
      }
      return TableKind::kValue;
    case TableKind::kFinger:
      if (!key.is_index && name == "device") return TableKind::kDevice;
      return !key.is_index && name == "trajectory" ? TableKind::kWaypoints : TableKind::kValue;
    case TableKind::kDevice:
      return !key.is_index && (name == "offset" || name == "rotation") ? TableKind::kVector : TableKind::kValue;
    case TableKind::kWaypoint:
      return !key.is_index && name == "p" ? TableKind::kVector : TableKind::kValue;
    case TableKind::kObjects: return TableKind::kObject;
    case TableKind::kFingers: return TableKind::kFinger;
    case TableKind::kExpects: return TableKind::kExpectation;
    case TableKind::kWaypoints: return TableKind::kWaypoint;
    default: return TableKind::kValue;
  }
}

const char* name_field(TableKind array) { return array == TableKind::kExpects ? "what" : "name"; }

const char* element_noun(TableKind array) {
  switch (array) {
    case TableKind::kObjects: return "object";
    case TableKind::kFingers: return "finger";
    case TableKind::kExpects: return "expectation";
    default: return "element";
  }
}

std::string element_segment(TableKind array, const LuaValue& table, std::size_t i) {
  const auto name_of = [&](std::size_t j) -> const std::string* {
    const LuaValue& element = table.entries[j].value;
    if (!element.is_table()) return nullptr;
    const LuaValue* name = element.find(name_field(array));
    return name != nullptr && name->type == LuaValue::Type::kString ? &name->text : nullptr;
  };
  const std::string* name = name_of(i);
  const std::string index = table.entries[i].key.str();
  if (name == nullptr || name->empty() || name->find_first_of(".=") != std::string::npos ||
      name->find_first_not_of("0123456789") == std::string::npos) {
    return index;
  }
  for (std::size_t j = 0; j < table.entries.size(); ++j) {
    const std::string* other = name_of(j);
    if (j != i && other != nullptr && *other == *name) return index;
  }
  return *name;
}

// ---------------------------------------------------------------------------------------------
// The whole scenario.

ScenarioParts convert_scenario(const LuaValue& root, const std::string& default_name,
                               const std::string& base_dir) {
  if (!root.is_table()) {
    throw ConversionError("the scenario must return a table (return { duration = ..., objects = "
                          "..., fingers = ... }), but it returned " + root.type_name());
  }
  const Record r(root, Where{}, TableKind::kRoot);
  ScenarioParts s;
  s.name = r.string_or("name", default_name);
  s.description = r.string_or("description", "");
  s.model.rates = read_rates(r.get("rates"));
  s.duration = finite_number(r.required("duration", "the run's length in s"), r.at("duration"));
  if (!(s.duration > 0.0)) fail(r.at("duration"), "must be > 0 s (got " + format_short(s.duration) + ")");
  if (const LuaValue* seed = r.get("seed")) {
    const std::int64_t value = integer(*seed, r.at("seed"));
    if (value < 0) fail(r.at("seed"), "must be an integer >= 0 (got " + std::to_string(value) + ")");
    s.seed = static_cast<std::uint64_t>(value);
  }
  s.model.gravity = r.vec3_or("gravity", s.model.gravity);
  s.model.integrator = Integrator::kImplicit;   // the scenario format's default (README, "Integrators")
  if (const LuaValue* i = r.get("integrator")) {
    const std::string name = choice(*i, r.at("integrator"), {"paper", "implicit"}, "integrator");
    s.model.integrator = name == "paper" ? Integrator::kPaper : Integrator::kImplicit;
  }
  if (const LuaValue* order = r.get("implicit_order")) {
    const std::int64_t value = integer(*order, r.at("implicit_order"));
    if (value != 1 && value != 2)
      fail(r.at("implicit_order"), "must be 1 (backward Euler) or 2 (BDF2) (got " + std::to_string(value) + ")");
    if (s.model.integrator != Integrator::kImplicit)
      fail(r.at("implicit_order"), "needs integrator = \"implicit\" (the paper's step has one order)");
    s.model.implicit_order = static_cast<int>(value);
  }
  if (const LuaValue* lm = r.get("local_model")) {
    if (lm->type != LuaValue::Type::kBoolean) fail(r.at("local_model"), "expected true or false, got " + lm->type_name());
    s.model.local_model = lm->boolean;
    if (s.model.local_model && s.model.integrator != Integrator::kImplicit) {
      fail(r.at("local_model"), "needs integrator = \"implicit\" (the paper's step has no local model)");
    }
  }
  if (const LuaValue* st = r.get("stability")) {
    s.refuse_unstable = choice(*st, r.at("stability"), {"warn", "refuse"}, "stability choice") == "refuse";
  }
  if (const LuaValue* g = r.get("gyroscopic")) {
    const std::string name = choice(*g, r.at("gyroscopic"), {"neglect", "explicit", "implicit"}, "gyroscopic");
    s.model.gyroscopic = name == "explicit" ? Gyroscopic::kExplicit
                       : name == "implicit" ? Gyroscopic::kImplicit : Gyroscopic::kNeglect;
  }
  s.model.floor = read_floor(r.get("floor"));
  s.model.sleep = read_sleep(r.get("sleep"));

  if (const LuaValue* objects = r.get("objects")) {
    const auto elements = array(*objects, r.at("objects"), "an array of objects { {name = ...}, ... }");
    for (std::size_t i = 0; i < elements.size(); ++i) s.model.bodies.push_back(object(*elements[i], i + 1, base_dir, s.files));
  }
  if (const LuaValue* fingers = r.get("fingers")) {
    const auto elements = array(*fingers, r.at("fingers"), "an array of fingers { {name = ...}, ... }");
    for (std::size_t i = 0; i < elements.size(); ++i) {
      FingerParts f = finger(*elements[i], i + 1);
      s.model.fingers.push_back(f.params);
      s.fingers.push_back(f.setup);
      s.trajectories.push_back(std::move(f.trajectory));
    }
  }
  if (const LuaValue* grasp = r.get("grasp")) {
    if (!grasp->is_table()) fail(r.at("grasp"), "expected a table, got " + grasp->type_name());
    const Record g(*grasp, r.at("grasp"), TableKind::kGrasp);
    GraspParams& out = s.model.grasp;
    if (const LuaValue* t = g.get("torsion")) {
      const std::string name = choice(*t, g.at("torsion"), {"none", "gravity_drop", "gimbal"}, "torsion");
      out.torsion = name == "gravity_drop" ? Torsion::kGravityDrop
                  : name == "gimbal" ? Torsion::kGimbal : Torsion::kNone;
    }
    out.critical_area = g.number_or("critical_area", out.critical_area);
    out.dead_band = g.number_or("dead_band", out.dead_band);
    out.torsional_damping = g.number_or("torsional_damping", out.torsional_damping);
    if (const LuaValue* f = g.get("gimbal_finger")) {
      const std::string name = string_value(*f, g.at("gimbal_finger"));
      for (std::size_t i = 0; i < s.model.fingers.size(); ++i) {
        if (s.model.fingers[i].name == name) out.gimbal_finger = static_cast<int>(i);
      }
      if (out.gimbal_finger < 0) fail(g.at("gimbal_finger"), "no finger is named '" + name + "'");
    }
  }
  if (const LuaValue* expect = r.get("expect")) {
    const auto elements = array(*expect, r.at("expect"), "an array of expectations { {what = ..., check = ...}, ... }");
    std::set<std::string> seen;
    for (std::size_t i = 0; i < elements.size(); ++i) {
      s.expectations.push_back(expectation(*elements[i], i + 1, s.duration));
      if (!seen.insert(s.expectations.back().what).second) {
        fail(Where{element_label("expect", i + 1, *elements[i], "what"), "what"},
             "the same sentence is used twice (each expectation needs its own)");
      }
    }
  }

  // The engine's own checks (rates divide servo, masses, inertias, materials, names).
  try {
    validate(s.model);
  } catch (const std::invalid_argument& e) {
    throw ConversionError(e.what());
  }
  // The ceilings (scenario.hpp): refused before a run commits memory or disk to them.
  const Rates& rates = s.model.rates;
  if (rates.servo > kMaxServoRate) {
    throw ConversionError("rates.servo: " + std::to_string(rates.servo) + " Hz is over the ceiling of " +
                          std::to_string(kMaxServoRate) + " Hz (10 times the fastest haptic servo loop; the trace "
                          "holds a quarter second of rows per table in memory)");
  }
  if (s.duration > kMaxDuration) {
    fail(r.at("duration"), format_short(s.duration) + " s is over the ceiling of " + format_short(kMaxDuration) +
                               " s (24 h of simulated time: " + format_short(s.duration * rates.servo) +
                               " servo ticks at " + std::to_string(rates.servo) + " Hz)");
  }
  // Every loop runs exactly duration x rate times, so the duration is a whole number of periods
  // of each loop; time is tick / servo, never accumulated, and exact while ticks < 2^53.
  const std::pair<const char*, int> loops[] = {
      {"servo", rates.servo}, {"haptic", rates.haptic}, {"physics", rates.physics}};
  for (const auto& [loop, rate] : loops) {
    const double count = s.duration * rate;
    if (!(std::abs(count - std::round(count)) <= 1e-9 * count)) {
      fail(r.at("duration"), format_short(s.duration) + " s is not a whole number of " + loop +
                             " periods at rates." + loop + " = " + std::to_string(rate) + " Hz (" +
                             format_short(count) + " ticks)");
    }
  }
  if (!(s.duration * rates.servo <= 9007199254740992.0)) {
    fail(r.at("duration"), format_short(s.duration) + " s is too long: more than 2^53 servo ticks");
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Parameters for the trace.

namespace {

std::string format_value(const LuaValue& value) {
  switch (value.type) {
    case LuaValue::Type::kBoolean: return value.boolean ? "true" : "false";
    case LuaValue::Type::kInteger: return std::to_string(value.integer);
    case LuaValue::Type::kNumber: return format_exact(value.number);
    case LuaValue::Type::kString: return value.text;
    default: return "<" + value.type_name() + ">";
  }
}

void flatten(const LuaValue& value, TableKind kind, const std::string& path,
             std::vector<std::string>& out) {
  if (value.type == LuaValue::Type::kFunction) return;
  if (!value.is_table()) {
    out.push_back(path + " = " + format_value(value));
    return;
  }
  if (value.entries.empty()) {
    out.push_back(path + " = {}");
    return;
  }
  // An array of numbers reads as --set takes it: "0,0,0.04".
  const bool numeric = value.array_length() > 0 &&
      std::all_of(value.entries.begin(), value.entries.end(),
                  [](const LuaValue::Entry& e) { return e.value.is_number(); });
  if (numeric) {
    std::string line = path + " = ";
    for (std::size_t i = 0; i < value.entries.size(); ++i) {
      if (i > 0) line += ",";
      line += format_value(value.entries[i].value);
    }
    out.push_back(line);
    return;
  }
  for (std::size_t i = 0; i < value.entries.size(); ++i) {
    const LuaValue::Entry& entry = value.entries[i];
    const std::string segment =
        is_named_array(kind) ? element_segment(kind, value, i) : entry.key.str();
    flatten(entry.value, child_kind(kind, entry.key), path.empty() ? segment : path + "." + segment,
            out);
  }
}

}  // namespace

std::vector<std::string> flatten_parameters(const LuaValue& root, const LuaValue& params) {
  std::vector<std::string> out;
  flatten(root, TableKind::kRoot, "", out);
  if (params.is_table() && !params.entries.empty()) flatten(params, TableKind::kValue, "", out);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace graspsim::scripting::detail
