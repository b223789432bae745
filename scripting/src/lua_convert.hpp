// The one place that converts between Lua values and C++ types: copies of scenario tables,
// --set values and param(), the `sim` table of expectations, and the results of trajectory and
// check functions.
//
// Two kinds of functions here. Readers use raw, non-allocating access only (lua_next,
// lua_rawgeti, lua_type, lua_tonumberx, lua_tolstring on strings): they raise no Lua error, so
// they may run in plain C++ and throw. Writers allocate, so they run inside
// LuaSandbox::protect() and must not own C++ objects with destructors.
#pragma once

#include <string>
#include <vector>

#include "graspsim/engine/math.hpp"
#include "graspsim/scripting/lua_sandbox.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "lua_value.hpp"
#include "overrides.hpp"

struct lua_State;

namespace graspsim::scripting::detail {

// Copies the value at stack index `index` (tables recursively, by raw access, in key order).
// With a sandbox, every function found gets a registry reference (taken under protect()).
// Throws ConversionError for a table that contains itself, keys that are neither strings nor
// integers, nesting deeper than 64 or more than 1,000,000 values.
LuaValue read_value(lua_State* state, int index, LuaSandbox* sandbox);

// Sets table[chain[0]][chain[1]]... = value in the table at stack index `table`, creating
// missing intermediate tables. Raw sets: no metamethods run.
void set_path(LuaSandbox& sandbox, int table, const std::vector<LuaKey>& chain,
              const SetValue& value);

// param(name, default), the global the scenario sees while it loads. Its upvalue is a light
// userdata pointing to the std::vector<Override> of the load, or null once loading is over.
int param_function(lua_State* state);
// Points param()'s upvalue at `overrides` (null: param() then raises "only while loading").
void set_param_overrides(LuaSandbox& sandbox, std::vector<Override>* overrides);

// The values param() returned while the file ran, by name (an empty nil value if none).
LuaValue read_params(lua_State* state);

// Pushes sim = {time, objects = {<name> = {...}}, fingers = {<name> = {...}}, initial = {...}}.
void push_sim(LuaSandbox& sandbox, const Snapshot& now, const Snapshot& initial);

// The read-only view trajectory functions get as their second argument: the same shape as `sim`
// (without `initial`), kept in the registry and written in place, so that after the first call
// an update allocates nothing (the names are interned strings, the tables exist).
void update_view(LuaSandbox& sandbox, const Snapshot& now);
// Pushes the view (nil before the first update_view). Raw access: raises nothing.
void push_view(lua_State* state);

// The results of a trajectory function, from stack index `first` on: x, y, z[, pitch] or
// {x, y, z[, pitch]} (pitch in rad, 0 when absent). Returns false (with `found` saying what was
// there) when they are not three or four numbers.
bool read_position(lua_State* state, int first, Vec3& position, double& pitch, std::string& found);

// The results of a check function at `first` and first + 1: a boolean, then nil, a string or a
// number. Returns false (with `found` naming the wrong type) when they are not.
bool read_check(lua_State* state, int first, bool& passed, std::string& detail, std::string& found);

// The value at `index` as text: nil, true, 42, %.17g for floats, strings as they are,
// "<table>" for the other types. Raises nothing (no __tostring).
std::string describe_value(lua_State* state, int index);

}  // namespace graspsim::scripting::detail
