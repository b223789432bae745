// Lua's C library functions whose work the VM's count hook never sees, made to pay for it: the
// pattern functions (string.find, string.match, string.gmatch, string.gsub) and the loops of
// string.rep and table.move. Their work is charged to the sandbox's instruction budget
// (LuaSandbox::charge), so `string.rep("a", 20000):find(string.rep(".-", 8) .. "b")`, which
// backtracks for hours, stops like an endless Lua loop: once the call's budget is spent.
// scripting/README.md, "Sandbox", states the bound.
#pragma once

struct lua_State;

namespace graspsim::scripting::detail {

// Work charged in one go: a matcher charges every kChargeEvery steps (and what is left when it
// returns), so the budget is overrun by less than this many steps.
inline constexpr long kChargeEvery = 4096;   // steps

// Replaces string.find, string.match, string.gmatch, string.gsub, string.rep and table.move in
// the state's string and table libraries (which must be open) with the charged versions.
// Called in a protected call (it sets table fields).
int install_charged_functions(lua_State* state);

}  // namespace graspsim::scripting::detail
