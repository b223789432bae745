// A finger trajectory given as a Lua function of time (and of the read-only simulation view),
// called at every servo tick.
#pragma once

#include <string>

#include "graspsim/hw/trajectory.hpp"
#include "graspsim/scripting/lua_sandbox.hpp"

namespace graspsim::scripting::detail {

class LuaTrajectory final : public hw::Trajectory {
 public:
  // `function_ref`: registry reference of the function in `sandbox`, which must outlive this.
  // `label` names the finger in messages: "fingers[1] 'thumb'".
  LuaTrajectory(LuaSandbox& sandbox, int function_ref, std::string path, std::string label);
  // Calls the function with t and the view (nil before the runner's first update_view) under
  // the per-call instruction budget; no C++ allocation unless it fails. Returns the position and
  // the gimbal pitch (0 unless the function returns a fourth value). Throws ScenarioError
  // (file:line and traceback, or what was returned instead of a finite x, y, z[, pitch]).
  hw::TrajectorySample sample(double t) override;

 private:
  LuaSandbox* sandbox_;
  int function_ref_;
  std::string path_;
  std::string label_;
};

}  // namespace graspsim::scripting::detail
