// The scenario format: which fields each table has, and the conversion of a scenario table
// (already copied out of Lua) into the Model, the finger set-ups, the trajectories and the
// expectations. Plain C++: errors are ConversionErrors naming the field.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "graspsim/engine/model.hpp"
#include "graspsim/hw/trajectory.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "lua_value.hpp"

namespace graspsim::scripting::detail {

// The kinds of tables in a scenario. Records have named fields; arrays are indexed 1..n; the
// elements of objects, fingers and expect are also addressed by their name (or `what`).
enum class TableKind {
  kRoot, kRates, kFloor, kMaterial, kGrasp, kSleep,
  kObjects, kObject, kFingers, kFinger, kWaypoints, kWaypoint, kExpects, kExpectation,
  kDevice,   // a finger's device = { default, scale, offset, rotation }
  kVector,   // {x, y, z} or {w, x, y, z}
  kValue,    // not a table of the format (a number, a string, a function...)
};

bool is_record(TableKind kind);
bool is_named_array(TableKind kind);   // objects, fingers, expect
// The fields of a record kind, in the documented order (empty for other kinds).
const std::vector<std::string>& fields_of(TableKind kind);
// The kind of the value under `key` in a table of kind `parent`.
TableKind child_kind(TableKind parent, const LuaKey& key);
// Named arrays: the field that names an element ("name"; "what" for expect) and the element's
// noun in messages ("object", "finger", "expectation").
const char* name_field(TableKind array);
const char* element_noun(TableKind array);
// The path segment for element i (0-based) of a named array: its name when that can be used in
// a dotted path (unique, no '.' or '=', not a number), else its index (1-based).
std::string element_segment(TableKind array, const LuaValue& table, std::size_t i);

struct TrajectoryParts {
  std::vector<hw::Waypoint> waypoints;
  hw::Interpolation interpolation = hw::Interpolation::kMinimumJerk;
  int function_ref = 0;   // registry reference of a Lua function of time, 0 for waypoints
};

struct ScenarioParts {
  std::string name;
  std::string description;
  Model model;
  double duration = 0.0;      // s
  std::uint64_t seed = 0;
  bool refuse_unstable = false;   // stability = "refuse"
  std::vector<FingerSetup> fingers;
  std::vector<TrajectoryParts> trajectories;   // one per finger
  std::vector<Expectation> expectations;
  std::vector<std::string> files;   // every mesh file read, as opened (Scenario::files)
};

// Checks and converts the scenario table. Functions in it must carry registry references.
// `default_name` is used when the table has no name; mesh files are found relative to
// `base_dir` (the scenario file's directory; "" for the working directory).
ScenarioParts convert_scenario(const LuaValue& root, const std::string& default_name,
                               const std::string& base_dir = "");

// Every value of the table except functions, and every value param() returned (`params`, by
// name), as sorted "path = value" lines with the paths --set takes
// ("objects.box.mass = 0.40000000000000002", "gravity = 0,0,-9.8100000000000005", "lift = 0.05").
std::vector<std::string> flatten_parameters(const LuaValue& root, const LuaValue& params);

}  // namespace graspsim::scripting::detail
