// A finger trajectory given as a Lua function of time.
#include "lua_trajectory.hpp"

#include <cmath>

#include <lua.hpp>

#include "lua_convert.hpp"
#include "messages.hpp"

namespace graspsim::scripting::detail {

LuaTrajectory::LuaTrajectory(LuaSandbox& sandbox, int function_ref, std::string path,
                             std::string label)
    : sandbox_(&sandbox), function_ref_(function_ref), path_(std::move(path)), label_(std::move(label)) {}

hw::TrajectorySample LuaTrajectory::sample(double t) {
  sandbox_->enter();   // before anything touches the state (the thread guard)
  lua_State* state = sandbox_->state();
  const int top = lua_gettop(state);
  const auto where = [&] { return label_ + " trajectory at t = " + format_short(t) + " s"; };
  if (!lua_checkstack(state, 4)) throw ScenarioError(path_ + ": " + where() + ": Lua stack overflow");
  lua_rawgeti(state, LUA_REGISTRYINDEX, function_ref_);
  lua_pushnumber(state, t);
  push_view(state);
  try {
    sandbox_->call(2, 4, Budget::kCall);
  } catch (const ScenarioError& e) {
    lua_settop(state, top);
    throw ScenarioError(with_context(e.what(), path_, where()));
  }
  hw::Vec3 p;
  double pitch = 0.0;
  std::string found;
  const bool ok = read_position(state, top + 1, p, pitch, found);
  lua_settop(state, top);
  if (!ok) {
    throw ScenarioError(path_ + ": " + where() + ": the function must return x, y, z (m) and "
                        "optionally the gimbal pitch (rad), or {x, y, z[, pitch]}, but returned " + found);
  }
  if (!p.allFinite()) {
    throw ScenarioError(path_ + ": " + where() + ": the function returned a non-finite position (" +
                        format_short(p.x()) + ", " + format_short(p.y()) + ", " +
                        format_short(p.z()) + ")");
  }
  if (!std::isfinite(pitch)) {
    throw ScenarioError(path_ + ": " + where() + ": the function returned a non-finite pitch (" +
                        format_short(pitch) + ")");
  }
  hw::TrajectorySample out;
  out.position = p;
  out.gimbal.y() = pitch;
  return out;
}

}  // namespace graspsim::scripting::detail
