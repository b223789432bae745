// A finger trajectory given as a Lua function of time.
#include "lua_trajectory.hpp"

#include <lua.hpp>

#include "lua_convert.hpp"
#include "messages.hpp"

namespace graspsim::scripting::detail {

LuaTrajectory::LuaTrajectory(LuaSandbox& sandbox, int function_ref, std::string path,
                             std::string label)
    : sandbox_(&sandbox), function_ref_(function_ref), path_(std::move(path)), label_(std::move(label)) {}

hw::Vec3 LuaTrajectory::position(double t) {
  lua_State* state = sandbox_->state();
  const int top = lua_gettop(state);
  const auto where = [&] { return label_ + " trajectory at t = " + format_short(t) + " s"; };
  if (!lua_checkstack(state, 4)) throw ScenarioError(path_ + ": " + where() + ": Lua stack overflow");
  lua_rawgeti(state, LUA_REGISTRYINDEX, function_ref_);
  lua_pushnumber(state, t);
  try {
    sandbox_->call(1, 3, Budget::kCall);
  } catch (const ScenarioError& e) {
    lua_settop(state, top);
    throw ScenarioError(with_context(e.what(), path_, where()));
  }
  hw::Vec3 p;
  std::string found;
  const bool ok = read_position(state, top + 1, p, found);
  lua_settop(state, top);
  if (!ok) {
    throw ScenarioError(path_ + ": " + where() + ": the function must return x, y, z (m) or "
                        "{x, y, z}, but returned " + found);
  }
  if (!p.allFinite()) {
    throw ScenarioError(path_ + ": " + where() + ": the function returned a non-finite position (" +
                        format_short(p.x()) + ", " + format_short(p.y()) + ", " +
                        format_short(p.z()) + ")");
  }
  return p;
}

}  // namespace graspsim::scripting::detail
