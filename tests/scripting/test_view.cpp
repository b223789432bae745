// The simulation view trajectories read: written in place, so that after the first write an
// update allocates nothing in Lua (the run loop writes it after every physics tick, up to 3000
// times a second).
#include <catch2/catch.hpp>

#include <lua.hpp>

#include "graspsim/scripting/lua_sandbox.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "lua_convert.hpp"

using graspsim::Vec3;
using namespace graspsim::scripting;

namespace {
Snapshot shaped(double x) {
  Snapshot s;
  s.time = x;
  for (const char* name : {"box", "lid"}) {
    ObjectSnapshot o;
    o.name = name;
    o.position = Vec3(x, 2 * x, 3 * x);
    o.floor_contacts = 4;
    s.objects.push_back(o);
  }
  for (const char* name : {"thumb", "index"}) {
    FingerSnapshot f;
    f.name = name;
    f.touching = "box";
    f.force = Vec3(x, 0, 0);
    s.fingers.push_back(f);
  }
  return s;
}
}  // namespace

// The count: the sandbox's allocator sees every byte Lua asks for. With the collector stopped,
// any allocation would show as growth (nothing is freed behind it). Tolerance zero: the claim is
// "no allocation", not "little".
TEST_CASE("updating the view allocates nothing after the first write", "[scripting][feedback]") {
  LuaSandbox sandbox;
  detail::update_view(sandbox, shaped(0.0));
  lua_gc(sandbox.state(), LUA_GCSTOP);
  const std::size_t before = sandbox.memory_used();
  for (int i = 1; i <= 1000; ++i) detail::update_view(sandbox, shaped(0.001 * i));
  CHECK(sandbox.memory_used() == before);
  // And the values are the last ones written: view.objects.lid.position[3] = 3 x 1.0.
  detail::push_view(sandbox.state());
  REQUIRE(lua_type(sandbox.state(), -1) == LUA_TUSERDATA);
  lua_getfield(sandbox.state(), -1, "objects");
  lua_getfield(sandbox.state(), -1, "lid");
  lua_getfield(sandbox.state(), -1, "position");
  lua_geti(sandbox.state(), -1, 3);
  CHECK(lua_tonumber(sandbox.state(), -1) == 3.0);
  lua_settop(sandbox.state(), 0);
  // A snapshot of another shape (one object fewer) builds the view anew instead of writing past
  // the list of tables.
  Snapshot fewer = shaped(2.0);
  fewer.objects.pop_back();
  detail::update_view(sandbox, fewer);
  detail::push_view(sandbox.state());
  lua_getfield(sandbox.state(), -1, "objects");
  lua_getfield(sandbox.state(), -1, "lid");
  CHECK(lua_isnil(sandbox.state(), -1));
  lua_settop(sandbox.state(), 0);
}
