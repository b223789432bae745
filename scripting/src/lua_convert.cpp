// Conversions between Lua values and C++ types (see lua_convert.hpp for the two rules).
#include "lua_convert.hpp"

#include <algorithm>
#include <cstdio>

#include <lua.hpp>

#include "messages.hpp"

namespace graspsim::scripting::detail {
namespace {

constexpr int kMaxDepth = 64;                 // nesting of tables in a scenario
constexpr std::size_t kMaxValues = 1'000'000;   // values in a scenario table, all levels

// ---------------------------------------------------------------------------------------------
// Readers: raw access only, so plain C++ that may throw.

void ensure_stack(lua_State* state, int slots) {
  if (!lua_checkstack(state, slots)) throw ConversionError("Lua stack overflow");
}

int take_reference(lua_State* state) {
  // index 1: int* for the result; index 2: the value to reference
  *static_cast<int*>(lua_touserdata(state, 1)) = luaL_ref(state, LUA_REGISTRYINDEX);
  return 0;
}

class Reader {
 public:
  Reader(lua_State* state, LuaSandbox* sandbox) : state_(state), sandbox_(sandbox) {}

  LuaValue read(int index) {
    if (++count_ > kMaxValues) {
      fail("the scenario table has more than " + std::to_string(kMaxValues) + " values");
    }
    LuaValue value;
    switch (lua_type(state_, index)) {
      case LUA_TNIL: break;
      case LUA_TBOOLEAN:
        value.type = LuaValue::Type::kBoolean;
        value.boolean = lua_toboolean(state_, index) != 0;
        break;
      case LUA_TNUMBER:
        if (lua_isinteger(state_, index)) {
          value.type = LuaValue::Type::kInteger;
          value.integer = lua_tointeger(state_, index);
          value.number = static_cast<double>(value.integer);
        } else {
          value.type = LuaValue::Type::kNumber;
          value.number = lua_tonumber(state_, index);
        }
        break;
      case LUA_TSTRING: {
        value.type = LuaValue::Type::kString;
        std::size_t length = 0;
        const char* text = lua_tolstring(state_, index, &length);
        value.text.assign(text, length);
        break;
      }
      case LUA_TFUNCTION:
        value.type = LuaValue::Type::kFunction;
        if (sandbox_ != nullptr) {
          ensure_stack(state_, 3);
          lua_pushvalue(state_, index);
          sandbox_->protect(take_reference, &value.ref, 1, 0);
        }
        break;
      case LUA_TTABLE:
        value.type = LuaValue::Type::kTable;
        read_table(index, value);
        break;
      default:
        value.type = LuaValue::Type::kOther;
        value.text = luaL_typename(state_, index);
        break;
    }
    return value;
  }

 private:
  void read_table(int index, LuaValue& value) {
    const void* identity = lua_topointer(state_, index);
    if (std::find(ancestors_.begin(), ancestors_.end(), identity) != ancestors_.end()) {
      fail("the table contains itself (a cycle)");
    }
    if (ancestors_.size() >= kMaxDepth) fail("tables nested deeper than 64 levels");
    ensure_stack(state_, 4);
    ancestors_.push_back(identity);
    lua_pushnil(state_);
    while (lua_next(state_, index) != 0) {   // key at -2, value at -1
      LuaKey key;
      if (lua_type(state_, -2) == LUA_TSTRING) {
        std::size_t length = 0;
        const char* name = lua_tolstring(state_, -2, &length);   // a string: no conversion
        key = LuaKey::named(std::string(name, length));
      } else if (lua_isinteger(state_, -2)) {
        key = LuaKey::at(lua_tointeger(state_, -2));
      } else {
        fail(std::string("keys must be names or integer indices, found a ") +
             luaL_typename(state_, -2) + " key");
      }
      path_.push_back(key);
      LuaValue element = read(lua_gettop(state_));
      path_.pop_back();
      value.entries.push_back(LuaValue::Entry{std::move(key), std::move(element)});
      lua_pop(state_, 1);
    }
    ancestors_.pop_back();
    std::sort(value.entries.begin(), value.entries.end(),
              [](const LuaValue::Entry& a, const LuaValue::Entry& b) { return a.key < b.key; });
  }

  [[noreturn]] void fail(const std::string& what) const {
    std::string where;
    for (const LuaKey& key : path_) {
      if (key.is_index) {
        where.append("[").append(key.str()).append("]");
      } else {
        if (!where.empty()) where.append(".");
        where.append(key.name);
      }
    }
    throw ConversionError(where.empty() ? what : where + ": " + what);
  }

  lua_State* state_;
  LuaSandbox* sandbox_;
  std::vector<const void*> ancestors_;   // tables being read, outermost first
  std::vector<LuaKey> path_;             // keys leading to the value being read
  std::size_t count_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Writers: run inside lua_pcall; no C++ objects with destructors in these frames.

void push_key(lua_State* state, const LuaKey& key) {
  if (key.is_index) {
    lua_pushinteger(state, static_cast<lua_Integer>(key.index));
  } else {
    lua_pushlstring(state, key.name.data(), key.name.size());
  }
}

void push_set_value(lua_State* state, const SetValue& value) {
  switch (value.type) {
    case SetValue::Type::kNil: lua_pushnil(state); break;
    case SetValue::Type::kBoolean: lua_pushboolean(state, value.boolean ? 1 : 0); break;
    case SetValue::Type::kInteger: lua_pushinteger(state, static_cast<lua_Integer>(value.integer)); break;
    case SetValue::Type::kNumber: lua_pushnumber(state, value.number); break;
    case SetValue::Type::kString: lua_pushlstring(state, value.text.data(), value.text.size()); break;
    case SetValue::Type::kArray:
      lua_createtable(state, static_cast<int>(value.elements.size()), 0);
      for (std::size_t i = 0; i < value.elements.size(); ++i) {
        push_set_value(state, value.elements[i]);
        lua_rawseti(state, -2, static_cast<lua_Integer>(i) + 1);
      }
      break;
  }
}

struct SetPath {
  const std::vector<LuaKey>* chain;
  const SetValue* value;
};

int set_path_protected(lua_State* state) {
  // index 1: SetPath*; index 2: the table
  const SetPath& set = *static_cast<const SetPath*>(lua_touserdata(state, 1));
  const std::vector<LuaKey>& chain = *set.chain;
  lua_pushvalue(state, 2);
  for (std::size_t i = 0; i + 1 < chain.size(); ++i) {
    push_key(state, chain[i]);
    lua_rawget(state, -2);
    if (lua_isnil(state, -1)) {
      lua_pop(state, 1);
      lua_newtable(state);
      push_key(state, chain[i]);
      lua_pushvalue(state, -2);
      lua_rawset(state, -4);
    } else if (!lua_istable(state, -1)) {
      return luaL_error(state, "'%s' is not a table", chain[i].is_index ? "(index)" : chain[i].name.c_str());
    }
    lua_remove(state, -2);
  }
  push_key(state, chain.back());
  push_set_value(state, *set.value);
  lua_rawset(state, -3);
  return 0;
}

int set_param_protected(lua_State* state) {
  lua_pushglobaltable(state);
  lua_pushliteral(state, "param");
  lua_rawget(state, -2);
  if (lua_iscfunction(state, -1)) {
    lua_pushvalue(state, 1);   // the light userdata
    lua_setupvalue(state, -2, 1);
  }
  return 0;
}

// The registry key of the table of param() values: the address of this variable (a light
// userdata key: reading it allocates nothing).
const char kParamsKey = 0;

// Records params[name] = the value at the top of the stack, for parameters().
int record_param(lua_State* state, const char* name) {
  const int value = lua_gettop(state);
  if (lua_rawgetp(state, LUA_REGISTRYINDEX, &kParamsKey) != LUA_TTABLE) {
    lua_pop(state, 1);
    lua_newtable(state);
    lua_pushvalue(state, -1);
    lua_rawsetp(state, LUA_REGISTRYINDEX, &kParamsKey);
  }
  lua_pushvalue(state, value);
  lua_setfield(state, -2, name);
  lua_settop(state, value);
  return 1;
}

int param_type_error(lua_State* state, const Override& chosen, const char* name,
                     const char* expected) {
  return luaL_error(state, "--set %s: param '%s' expects %s, like its default", chosen.text.c_str(),
                    name, expected);
}

// Tables of the `sim` shape are written in place: write_state() reuses the tables it finds
// (numbers overwritten, nothing allocated after the first time) and creates the missing ones, so
// one function fills both a fresh `sim` for a check and the persistent view trajectories read.
// In the view every table is behind a read-only proxy (below); open() looks through it.

// Where write_state() finds the tables it writes into: by key (looking through read-only
// proxies; a check's fresh `sim`, and the view's first update, which also lists every table it
// opens, in order, in the table at `list`), or, for the view's later updates, from that list in
// the same order: one lua_rawgeti per table instead of a key lookup and a proxy.
struct Tables {
  int list = 0;         // absolute stack index of the list of tables, or 0
  bool record = false;  // true: open by key and append to the list; false: take from the list
  lua_Integer next = 0; // tables taken or appended so far
};

// The table under the key at the top of the stack in the table at absolute index `parent`:
// replaces the key with it (the data behind a read-only proxy), creating it if absent.
void open(lua_State* state, int parent, int narray, int nrecord, Tables& tables) {
  lua_pushvalue(state, -1);
  lua_rawget(state, parent);   // key value
  if (lua_type(state, -1) == LUA_TTABLE) {
    lua_remove(state, -2);
  } else if (lua_type(state, -1) == LUA_TUSERDATA && lua_getmetatable(state, -1)) {   // key proxy mt
    lua_pushliteral(state, "__index");
    lua_rawget(state, -2);     // key proxy mt data
    lua_replace(state, -4);
    lua_pop(state, 2);
  } else {
    lua_pop(state, 1);
    lua_createtable(state, narray, nrecord);   // key table
    lua_pushvalue(state, -2);
    lua_pushvalue(state, -2);
    lua_rawset(state, parent);
    lua_remove(state, -2);
  }
  if (tables.record) {
    lua_pushvalue(state, -1);
    lua_rawseti(state, tables.list, ++tables.next);
  }
}

void open_field(lua_State* state, int parent, const char* key, int narray, int nrecord, Tables& tables) {
  if (tables.list != 0 && !tables.record) {
    lua_rawgeti(state, tables.list, ++tables.next);
    return;
  }
  lua_pushstring(state, key);
  open(state, parent, narray, nrecord, tables);
}

void open_index(lua_State* state, int parent, lua_Integer i, int narray, int nrecord, Tables& tables) {
  if (tables.list != 0 && !tables.record) {
    lua_rawgeti(state, tables.list, ++tables.next);
    return;
  }
  lua_pushinteger(state, i);
  open(state, parent, narray, nrecord, tables);
}

void set_number(lua_State* state, int table, const char* key, double value) {
  lua_pushstring(state, key);
  lua_pushnumber(state, value);
  lua_rawset(state, table);
}

void write_numbers(lua_State* state, int parent, const char* key, const double* values, int n,
                   Tables& tables) {
  open_field(state, parent, key, n, 0, tables);
  for (int i = 0; i < n; ++i) {
    lua_pushnumber(state, values[i]);
    lua_rawseti(state, -2, i + 1);
  }
  lua_pop(state, 1);
}

void write_vec3(lua_State* state, int parent, const char* key, const Vec3& v, Tables& tables) {
  const double values[3] = {v.x(), v.y(), v.z()};
  write_numbers(state, parent, key, values, 3, tables);
}

const char* phase_name(ContactPhase phase) {
  switch (phase) {
    case ContactPhase::kStick: return "stick";
    case ContactPhase::kSlip: return "slip";
    case ContactPhase::kFree: break;
  }
  return "free";
}

// Writes snapshot `s` into the table at absolute index `table`.
void write_state(lua_State* state, int table, const Snapshot& s, Tables& tables) {
  set_number(state, table, "time", s.time);
  lua_pushliteral(state, "local_model");
  lua_pushboolean(state, s.local_model ? 1 : 0);
  lua_rawset(state, table);
  open_field(state, table, "objects", 0, static_cast<int>(s.objects.size()), tables);
  const int objects = lua_gettop(state);
  for (const ObjectSnapshot& o : s.objects) {
    open_field(state, objects, o.name.c_str(), 0, 7, tables);
    const int t = lua_gettop(state);
    write_vec3(state, t, "position", o.position, tables);
    const double q[4] = {o.orientation.w(), o.orientation.x(), o.orientation.y(), o.orientation.z()};
    write_numbers(state, t, "orientation", q, 4, tables);
    open_field(state, t, "rotation", 3, 0, tables);
    const int rows = lua_gettop(state);
    const Mat3 r = o.orientation.toRotationMatrix();
    for (int i = 0; i < 3; ++i) {
      open_index(state, rows, i + 1, 3, 0, tables);
      for (int j = 0; j < 3; ++j) {
        lua_pushnumber(state, r(i, j));
        lua_rawseti(state, -2, j + 1);
      }
      lua_pop(state, 1);
    }
    lua_pop(state, 1);
    write_vec3(state, t, "velocity", o.velocity, tables);
    write_vec3(state, t, "angular_velocity", o.angular_velocity, tables);
    lua_pushliteral(state, "floor_contacts");
    lua_pushinteger(state, o.floor_contacts);
    lua_rawset(state, t);
    lua_pop(state, 1);
  }
  lua_pop(state, 1);
  open_field(state, table, "fingers", 0, static_cast<int>(s.fingers.size()), tables);
  const int fingers = lua_gettop(state);
  for (const FingerSnapshot& f : s.fingers) {
    open_field(state, fingers, f.name.c_str(), 0, 7, tables);
    const int t = lua_gettop(state);
    write_vec3(state, t, "hip", f.hip, tables);
    write_vec3(state, t, "god_object", f.god_object, tables);
    write_vec3(state, t, "force", f.force, tables);
    lua_pushliteral(state, "touching");
    lua_pushlstring(state, f.touching.data(), f.touching.size());
    lua_rawset(state, t);
    lua_pushliteral(state, "phase");
    lua_pushstring(state, phase_name(f.phase));
    lua_rawset(state, t);
    set_number(state, t, "slip", f.slip);
    lua_pop(state, 1);
  }
  lua_pop(state, 1);
}

void push_state(lua_State* state, const Snapshot& s, Tables& tables) {
  lua_createtable(state, 0, 4);
  write_state(state, lua_gettop(state), s, tables);
}

struct SimArguments {
  const Snapshot* now;
  const Snapshot* initial;
};

int push_sim_protected(lua_State* state) {
  const SimArguments& sim = *static_cast<const SimArguments*>(lua_touserdata(state, 1));
  Tables by_key;
  push_state(state, *sim.now, by_key);
  push_state(state, *sim.initial, by_key);
  lua_setfield(state, -2, "initial");
  return 1;
}

// ---------------------------------------------------------------------------------------------
// The read-only view: every table of the `sim` shape sits behind a full userdata whose metatable
// reads through to it (__index = the table, __len, __pairs) and refuses writes (__newindex), with
// a protected metatable. A userdata, not an empty table, so that rawset cannot shadow a field.

// The registry keys of the view (its root proxy) and of the list of its data tables in the order
// write_state() opens them: the addresses of these variables.
const char kViewKey = 0;
const char kViewTablesKey = 0;

int view_newindex(lua_State* state) {
  const char* key = lua_type(state, 2) == LUA_TSTRING ? lua_tostring(state, 2) : nullptr;
  if (key != nullptr) {
    return luaL_error(state, "the simulation view is read-only (cannot set field '%s')", key);
  }
  return luaL_error(state, "the simulation view is read-only (cannot set an element)");
}

// The data table behind the proxy at index 1.
void view_data(lua_State* state) {
  lua_getmetatable(state, 1);
  lua_pushliteral(state, "__index");
  lua_rawget(state, -2);
}

int view_len(lua_State* state) {
  view_data(state);
  lua_pushinteger(state, static_cast<lua_Integer>(lua_rawlen(state, -1)));
  return 1;
}

int view_next(lua_State* state) {   // next over a proxy's data, values as the proxy gives them
  lua_settop(state, 2);
  view_data(state);                  // proxy key mt data
  lua_pushvalue(state, 2);
  if (lua_next(state, 4) == 0) return 0;
  return 2;
}

int view_pairs(lua_State* state) {
  lua_pushcfunction(state, view_next);
  lua_pushvalue(state, 1);
  lua_pushnil(state);
  return 3;
}

// Replaces every table reachable from the table at the top of the stack, and that table itself,
// by a read-only proxy.
void seal(lua_State* state) {
  luaL_checkstack(state, 8, "sealing the simulation view");
  const int data = lua_gettop(state);
  lua_pushnil(state);
  while (lua_next(state, data) != 0) {   // key value
    if (lua_type(state, -1) == LUA_TTABLE) {
      seal(state);                       // key proxy
      lua_pushvalue(state, -2);
      lua_insert(state, -2);             // key key proxy
      lua_rawset(state, data);           // an existing key: allowed while traversing
    } else {
      lua_pop(state, 1);
    }
  }
  lua_newuserdatauv(state, 0, 0);        // data proxy
  lua_createtable(state, 0, 5);          // data proxy mt
  lua_pushvalue(state, data);
  lua_setfield(state, -2, "__index");
  lua_pushcfunction(state, view_newindex);
  lua_setfield(state, -2, "__newindex");
  lua_pushcfunction(state, view_len);
  lua_setfield(state, -2, "__len");
  lua_pushcfunction(state, view_pairs);
  lua_setfield(state, -2, "__pairs");
  lua_pushliteral(state, "read-only");
  lua_setfield(state, -2, "__metatable");
  lua_setmetatable(state, -2);           // data proxy
  lua_replace(state, data);              // proxy
}

int update_view_protected(lua_State* state) {
  const Snapshot& now = *static_cast<const Snapshot*>(lua_touserdata(state, 1));
  // The tables write_state() opens: objects, 9 per object (itself, position, orientation,
  // rotation and its 3 rows, velocity, angular_velocity), fingers, 4 per finger (itself, hip,
  // god_object, force). A snapshot of another shape than the first builds the view anew.
  const lua_Unsigned tables = 2 + 9 * now.objects.size() + 4 * now.fingers.size();
  lua_rawgetp(state, LUA_REGISTRYINDEX, &kViewTablesKey);
  const bool same_shape = lua_type(state, -1) == LUA_TTABLE && lua_rawlen(state, -1) == tables;
  lua_pop(state, 1);
  if (same_shape && lua_rawgetp(state, LUA_REGISTRYINDEX, &kViewKey) == LUA_TUSERDATA) {
    lua_getmetatable(state, -1);
    lua_pushliteral(state, "__index");
    lua_rawget(state, -2);                                   // proxy mt data
    lua_rawgetp(state, LUA_REGISTRYINDEX, &kViewTablesKey);  // proxy mt data list
    Tables from_list{lua_gettop(state), false, 0};
    write_state(state, lua_gettop(state) - 1, now, from_list);
    return 0;
  }
  lua_settop(state, 1);
  lua_newtable(state);                                       // list
  lua_pushvalue(state, -1);
  lua_rawsetp(state, LUA_REGISTRYINDEX, &kViewTablesKey);
  Tables record{lua_gettop(state), true, 0};
  push_state(state, now, record);                            // list data
  seal(state);                                               // list proxy
  lua_rawsetp(state, LUA_REGISTRYINDEX, &kViewKey);
  return 0;
}

std::string lua_number_text(lua_State* state, int index) {
  if (lua_isinteger(state, index)) return std::to_string(lua_tointeger(state, index));
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.14g", lua_tonumber(state, index));   // as tostring()
  return buffer;
}

}  // namespace

LuaValue read_value(lua_State* state, int index, LuaSandbox* sandbox) {
  const int top = lua_gettop(state);
  index = lua_absindex(state, index);
  try {
    Reader reader(state, sandbox);
    LuaValue value = reader.read(index);
    lua_settop(state, top);
    return value;
  } catch (...) {
    lua_settop(state, top);
    throw;
  }
}

void set_path(LuaSandbox& sandbox, int table, const std::vector<LuaKey>& chain,
              const SetValue& value) {
  lua_State* state = sandbox.state();
  ensure_stack(state, 3);
  lua_pushvalue(state, table);
  SetPath set{&chain, &value};
  sandbox.protect(set_path_protected, &set, 1, 0);
}

int param_function(lua_State* state) {
  auto* overrides = static_cast<std::vector<Override>*>(lua_touserdata(state, lua_upvalueindex(1)));
  if (overrides == nullptr) {
    return luaL_error(state, "param() can only be called while the scenario file runs (call it "
                             "at the top of the file and keep the value in a local)");
  }
  const char* name = luaL_checkstring(state, 1);
  Override* chosen = nullptr;
  for (Override& o : *overrides) {   // the last --set of a name wins
    if (o.path == name) {
      o.used = true;
      chosen = &o;
    }
  }
  if (chosen == nullptr) {
    lua_settop(state, 2);   // the default (nil when there is none)
    return record_param(state, name);
  }
  const SetValue& value = chosen->value;
  const bool is_number = value.type == SetValue::Type::kInteger || value.type == SetValue::Type::kNumber;
  switch (lua_type(state, 2)) {
    case LUA_TNONE:
    case LUA_TNIL:
      push_set_value(state, value);
      return record_param(state, name);
    case LUA_TBOOLEAN:
      if (value.type != SetValue::Type::kBoolean) return param_type_error(state, *chosen, name, "a boolean (true or false)");
      push_set_value(state, value);
      return record_param(state, name);
    case LUA_TNUMBER:
      if (!is_number) return param_type_error(state, *chosen, name, "a number");
      push_set_value(state, value);
      return record_param(state, name);
    case LUA_TSTRING:
      lua_pushlstring(state, value.text.data(), value.text.size());
      return record_param(state, name);
    case LUA_TTABLE:
      if (is_number) {
        lua_createtable(state, 1, 0);
        push_set_value(state, value);
        lua_rawseti(state, -2, 1);
        return record_param(state, name);
      }
      if (value.type != SetValue::Type::kArray) {
        return param_type_error(state, *chosen, name, "numbers separated by commas (like 0,0,0.1)");
      }
      push_set_value(state, value);
      return record_param(state, name);
    default:
      return luaL_error(state, "param '%s': the default must be a boolean, number, string or table, "
                               "not a %s", name, luaL_typename(state, 2));
  }
}

void set_param_overrides(LuaSandbox& sandbox, std::vector<Override>* overrides) {
  sandbox.protect(set_param_protected, overrides, 0, 0);
}

LuaValue read_params(lua_State* state) {
  ensure_stack(state, 1);
  lua_rawgetp(state, LUA_REGISTRYINDEX, &kParamsKey);
  LuaValue params = read_value(state, -1, nullptr);
  lua_pop(state, 1);
  return params;
}

void push_sim(LuaSandbox& sandbox, const Snapshot& now, const Snapshot& initial) {
  SimArguments sim{&now, &initial};
  sandbox.protect(push_sim_protected, &sim, 0, 1);
}

void update_view(LuaSandbox& sandbox, const Snapshot& now) {
  sandbox.protect(update_view_protected, const_cast<Snapshot*>(&now), 0, 0);
}

void push_view(lua_State* state) {
  lua_rawgetp(state, LUA_REGISTRYINDEX, &kViewKey);
}

bool read_position(lua_State* state, int first, Vec3& position, double& pitch, std::string& found) {
  pitch = 0.0;
  if (lua_type(state, first) == LUA_TTABLE) {
    const lua_Unsigned length = lua_rawlen(state, first);
    if (!lua_checkstack(state, 1)) {
      found = "(Lua stack overflow)";
      return false;
    }
    bool ok = length == 3 || length == 4;
    for (lua_Unsigned i = 0; ok && i < length; ++i) {
      lua_rawgeti(state, first, static_cast<lua_Integer>(i) + 1);
      ok = lua_type(state, -1) == LUA_TNUMBER;
      if (ok) (i < 3 ? position[static_cast<int>(i)] : pitch) = lua_tonumber(state, -1);
      lua_pop(state, 1);
    }
    if (!ok) found = "a table that is not {x, y, z} or {x, y, z, pitch} (" + std::to_string(length) + " elements)";
    return ok;
  }
  const int pitch_type = lua_type(state, first + 3);
  bool ok = pitch_type == LUA_TNUMBER || pitch_type == LUA_TNIL || pitch_type == LUA_TNONE;
  for (int i = 0; i < 3; ++i) ok = ok && lua_type(state, first + i) == LUA_TNUMBER;
  if (!ok) {
    found.clear();
    for (int j = 0; j < 4; ++j) {
      if (j == 3 && lua_isnoneornil(state, first + 3)) break;
      found += (j == 0 ? "" : ", ") + std::string(luaL_typename(state, first + j));
    }
    found = "(" + found + ")";
    return false;
  }
  for (int i = 0; i < 3; ++i) position[i] = lua_tonumber(state, first + i);
  if (pitch_type == LUA_TNUMBER) pitch = lua_tonumber(state, first + 3);
  return true;
}

bool read_check(lua_State* state, int first, bool& passed, std::string& detail, std::string& found) {
  if (lua_type(state, first) != LUA_TBOOLEAN) {
    found = std::string("check must return a boolean, got ") + luaL_typename(state, first);
    return false;
  }
  passed = lua_toboolean(state, first) != 0;
  switch (lua_type(state, first + 1)) {
    case LUA_TNIL: detail.clear(); return true;
    case LUA_TNUMBER: detail = lua_number_text(state, first + 1); return true;
    case LUA_TSTRING: {
      std::size_t length = 0;
      const char* text = lua_tolstring(state, first + 1, &length);
      detail.assign(text, length);
      return true;
    }
    default:
      found = std::string("check's second result (the message) must be a string, got ") +
              luaL_typename(state, first + 1);
      return false;
  }
}

std::string describe_value(lua_State* state, int index) {
  switch (lua_type(state, index)) {
    case LUA_TNIL: return "nil";
    case LUA_TBOOLEAN: return lua_toboolean(state, index) ? "true" : "false";
    case LUA_TNUMBER:
      return lua_isinteger(state, index) ? std::to_string(lua_tointeger(state, index))
                                         : format_exact(lua_tonumber(state, index));
    case LUA_TSTRING: {
      std::size_t length = 0;
      const char* text = lua_tolstring(state, index, &length);
      return std::string(text, length);
    }
    default: return std::string("<") + luaL_typename(state, index) + ">";
  }
}

}  // namespace graspsim::scripting::detail
