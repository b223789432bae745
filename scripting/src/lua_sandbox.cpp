// The sandboxed Lua state: allocator with a limit, count hook with a budget, library allow-list,
// strict globals, seeded math.random, protected loading and calling.
#include "graspsim/scripting/lua_sandbox.hpp"

#include <cstdio>
#include <cstdlib>

#include <lua.hpp>

#include "lua_convert.hpp"
#include "lua_patterns.hpp"

namespace graspsim::scripting {
namespace {

constexpr int kHookInterval = 1000;   // instructions between two calls of the count hook

// Last resort: a Lua error outside any lua_pcall is a bug in this module, never bad input.
int panic(lua_State* state) {
  const char* message = lua_tostring(state, -1);
  std::fprintf(stderr, "graspsim: Lua error outside a protected call (a bug in graspsim's "
               "scripting module): %s\n", message != nullptr ? message : "(no message)");
  std::fflush(stderr);
  std::abort();
}

// Message handler of every call: the message with a traceback (works without the debug library).
int message_handler(lua_State* state) {
  const char* message = lua_tostring(state, 1);
  if (message == nullptr) {
    if (luaL_callmeta(state, 1, "__tostring") && lua_type(state, -1) == LUA_TSTRING) {
      message = lua_tostring(state, -1);
    } else {
      message = lua_pushfstring(state, "(error object is a %s value)", luaL_typename(state, 1));
    }
  }
  luaL_traceback(state, state, message, 1);
  return 1;
}

// print(...): one "[lua] a\tb" line on stderr.
int print_to_stderr(lua_State* state) {
  const int n = lua_gettop(state);
  luaL_Buffer line;
  luaL_buffinit(state, &line);
  luaL_addstring(&line, "[lua] ");
  for (int i = 1; i <= n; ++i) {
    if (i > 1) luaL_addchar(&line, '\t');
    luaL_tolstring(state, i, nullptr);
    luaL_addvalue(&line);
  }
  luaL_addchar(&line, '\n');
  luaL_pushresult(&line);
  std::size_t length = 0;
  const char* text = lua_tolstring(state, -1, &length);
  std::fwrite(text, 1, length, stderr);
  std::fflush(stderr);
  return 0;
}

// Calls the wrapped library function (upvalue 1) with the wrapper's arguments, returning its
// results. Its errors get the caller's file:line: raised from a C function called by a C
// function, they would carry no place.
int call_wrapped(lua_State* state) {
  lua_pushvalue(state, lua_upvalueindex(1));
  lua_insert(state, 1);
  const int status = lua_pcall(state, lua_gettop(state) - 1, LUA_MULTRET, 0);
  if (status == LUA_OK) return lua_gettop(state);
  if (status == LUA_ERRRUN && lua_type(state, -1) == LUA_TSTRING) {
    luaL_where(state, 1);
    lua_insert(state, -2);
    lua_concat(state, 2);
  }
  return lua_error(state);
}

// math.randomseed without an argument would seed from the clock: refuse it.
int randomseed_checked(lua_State* state) {
  if (lua_isnoneornil(state, 1)) {
    return luaL_error(state, "math.randomseed needs a seed (runs must be reproducible; the "
                             "scenario's seed is already set)");
  }
  return call_wrapped(state);
}

// setmetatable refusing __gc: Lua runs finalizers with hooks off, so the instruction budget
// could not stop an endless loop in one. (A __gc added to a metatable after setmetatable never
// runs: Lua marks objects for finalization only here.)
int setmetatable_checked(lua_State* state) {
  luaL_checktype(state, 1, LUA_TTABLE);   // named 'setmetatable' in the message, not '?'
  if (lua_type(state, 2) == LUA_TTABLE) {
    lua_pushliteral(state, "__gc");
    const int type = lua_rawget(state, 2);
    lua_pop(state, 1);
    if (type != LUA_TNIL) {
      return luaL_error(state, "__gc metamethods are not allowed in scenarios (the instruction "
                               "budget cannot stop a finalizer)");
    }
  }
  return call_wrapped(state);
}

int open_libraries(lua_State* state) {
  static const luaL_Reg kLibraries[] = {
      {LUA_GNAME, luaopen_base},          {LUA_TABLIBNAME, luaopen_table},
      {LUA_STRLIBNAME, luaopen_string},   {LUA_MATHLIBNAME, luaopen_math},
      {LUA_UTF8LIBNAME, luaopen_utf8},    {LUA_COLIBNAME, luaopen_coroutine},
  };
  for (const luaL_Reg& library : kLibraries) {
    luaL_requiref(state, library.name, library.func, 1);
    lua_pop(state, 1);
  }
  lua_pushglobaltable(state);
  // No file access and no loading of code other than the scenario itself.
  for (const char* name : {"dofile", "loadfile", "load", "require"}) {
    lua_pushnil(state);
    lua_setfield(state, -2, name);
  }
  lua_pushcfunction(state, print_to_stderr);
  lua_setfield(state, -2, "print");
  lua_getfield(state, -1, "setmetatable");
  lua_pushcclosure(state, setmetatable_checked, 1);
  lua_setfield(state, -2, "setmetatable");
  lua_getfield(state, -1, LUA_STRLIBNAME);
  lua_pushnil(state);
  lua_setfield(state, -2, "dump");
  lua_pop(state, 1);
  // The pattern functions, string.rep and table.move do unbounded work in C, where the count
  // hook never runs: these versions charge it to the budget.
  detail::install_charged_functions(state);
  lua_getfield(state, -1, LUA_MATHLIBNAME);
  lua_getfield(state, -1, "randomseed");
  lua_pushcclosure(state, randomseed_checked, 1);
  lua_setfield(state, -2, "randomseed");
  lua_pop(state, 2);
  return 0;
}

// __index and __newindex of the locked global table.
int undefined_global(lua_State* state) {
  if (lua_type(state, 2) == LUA_TSTRING) {
    return luaL_error(state, "undefined global '%s'", lua_tostring(state, 2));
  }
  return luaL_error(state, "undefined global (a %s key)", luaL_typename(state, 2));
}
int new_global(lua_State* state) {
  if (lua_type(state, 2) == LUA_TSTRING) {
    return luaL_error(state, "assignment to undefined global '%s' (use local)",
                      lua_tostring(state, 2));
  }
  return luaL_error(state, "assignment to undefined global (a %s key; use local)",
                    luaL_typename(state, 2));
}

int lock_globals_protected(lua_State* state) {
  lua_pushglobaltable(state);
  lua_createtable(state, 0, 3);
  lua_pushcfunction(state, undefined_global);
  lua_setfield(state, -2, "__index");
  lua_pushcfunction(state, new_global);
  lua_setfield(state, -2, "__newindex");
  lua_pushliteral(state, "the global table is locked");
  lua_setfield(state, -2, "__metatable");   // getmetatable(_G) shows this; setmetatable fails
  lua_setmetatable(state, -2);
  return 0;
}

struct Registration {
  const char* name;
  LuaSandbox::CFunction function;
  void* upvalue;
};
int register_global_protected(lua_State* state) {
  const auto* registration = static_cast<const Registration*>(lua_touserdata(state, 1));
  lua_pushglobaltable(state);
  lua_pushlightuserdata(state, registration->upvalue);
  lua_pushcclosure(state, registration->function, 1);
  lua_setfield(state, -2, registration->name);
  return 0;
}

int seed_random_protected(lua_State* state) {
  const auto seed = *static_cast<const std::int64_t*>(lua_touserdata(state, 1));
  lua_pushglobaltable(state);
  lua_pushliteral(state, LUA_MATHLIBNAME);
  lua_rawget(state, -2);
  lua_pushliteral(state, "randomseed");
  lua_rawget(state, -2);
  lua_pushinteger(state, static_cast<lua_Integer>(seed));
  lua_call(state, 1, 0);
  return 0;
}

void ensure_stack(lua_State* state, int slots) {
  if (!lua_checkstack(state, slots)) throw ScenarioError("Lua stack overflow");
}

}  // namespace

LuaSandbox::LuaSandbox(const SandboxLimits& limits) : limits_(limits) {
  state_ = lua_newstate(&LuaSandbox::allocate, this);
  if (state_ == nullptr) throw ScenarioError("cannot create a Lua state (out of memory)");
  lua_atpanic(state_, panic);
  try {
    protect(open_libraries, nullptr, 0, 0);
    seed_random(0);
  } catch (...) {
    lua_close(state_);
    throw;
  }
}

// No Lua code runs while the state closes: setmetatable refuses __gc, so there are no finalizers.
LuaSandbox::~LuaSandbox() { lua_close(state_); }

// Lua's allocator contract: new_size == 0 frees; when block is null, old_size is a type tag.
// Refusing (null) makes Lua collect garbage and retry once, then raise its memory error.
void* LuaSandbox::allocate(void* self, void* block, std::size_t old_size, std::size_t new_size) {
  auto* sandbox = static_cast<LuaSandbox*>(self);
  // Counted, not refused: an allocator may not throw through Lua (the entry points refuse).
  if (std::this_thread::get_id() == sandbox->forbidden_thread_.load(std::memory_order_relaxed))
    sandbox->forbidden_uses_.fetch_add(1, std::memory_order_relaxed);
  const std::size_t old_bytes = block != nullptr ? old_size : 0;
  if (new_size == 0) {
    std::free(block);
    sandbox->used_bytes_ -= old_bytes;
    return nullptr;
  }
  const std::size_t limit = sandbox->limits_.memory_mib << 20;
  if (new_size > old_bytes && sandbox->used_bytes_ + (new_size - old_bytes) > limit) {
    sandbox->memory_limit_hit_ = true;
    return nullptr;
  }
  void* resized = std::realloc(block, new_size);
  if (resized == nullptr) {
    if (new_size <= old_bytes) return block;   // Lua assumes shrinking never fails
    return nullptr;
  }
  sandbox->used_bytes_ = sandbox->used_bytes_ - old_bytes + new_size;
  return resized;
}

// Runs every kHookInterval instructions of Lua code (in any coroutine). Once the budget is spent
// it raises on every instruction, so a script that catches the error with pcall cannot go on.
void LuaSandbox::count_hook(lua_State* state, lua_Debug* debug) {
  void* self = nullptr;
  lua_getallocf(state, &self);
  auto* sandbox = static_cast<LuaSandbox*>(self);
  sandbox->instructions_ += lua_gethookcount(state);
  if (sandbox->instructions_ <= sandbox->budget_) return;
  if (lua_gethookcount(state) != 1) {
    lua_sethook(state, &LuaSandbox::count_hook, LUA_MASKCOUNT, 1);
    sandbox->hook_every_instruction_ = true;
  }
  lua_getinfo(state, "Sl", debug);
  lua_pushfstring(state, "%s:%d: instruction budget of %I instructions exceeded (an endless loop?)",
                  debug->short_src, debug->currentline, static_cast<lua_Integer>(sandbox->budget_));
  lua_error(state);
}

void LuaSandbox::charge(lua_State* state, long long steps, const char* what) {
  void* self = nullptr;
  lua_getallocf(state, &self);
  auto* sandbox = static_cast<LuaSandbox*>(self);
  if (steps <= sandbox->budget_ - sandbox->instructions_) {   // no overflow: steps may be 2^63 - 1
    sandbox->instructions_ += steps;
    return;
  }
  sandbox->instructions_ = sandbox->budget_ + 1;
  if (!sandbox->hook_every_instruction_) {
    lua_sethook(state, &LuaSandbox::count_hook, LUA_MASKCOUNT, 1);
    sandbox->hook_every_instruction_ = true;
  }
  luaL_error(state, "instruction budget of %I instructions exceeded in %s", static_cast<lua_Integer>(sandbox->budget_),
             what);
}

void LuaSandbox::start_budget(Budget budget) {
  instructions_ = 0;
  budget_ = budget == Budget::kLoad ? limits_.load_instructions : limits_.call_instructions;
  memory_limit_hit_ = false;
  if (hook_every_instruction_ || lua_gethook(state_) == nullptr) {
    lua_sethook(state_, &LuaSandbox::count_hook, LUA_MASKCOUNT, kHookInterval);
    hook_every_instruction_ = false;
  }
}

void LuaSandbox::register_global(const char* name, CFunction fn, void* upvalue) {
  Registration registration{name, fn, upvalue};
  protect(register_global_protected, &registration, 0, 0);
}

void LuaSandbox::lock_globals() { protect(lock_globals_protected, nullptr, 0, 0); }

void LuaSandbox::seed_random(std::int64_t seed) { protect(seed_random_protected, &seed, 0, 0); }

void LuaSandbox::load(std::string_view source, const std::string& path) {
  ensure_stack(state_, 2);
  const std::string chunkname = "@" + path;
  start_budget(Budget::kLoad);
  const int status = luaL_loadbufferx(state_, source.data(), source.size(), chunkname.c_str(), "t");
  if (status != LUA_OK) throw_error(status);
  // Remember how Lua abbreviates this chunk's name in messages (long paths become "...tail").
  lua_Debug info;
  lua_pushvalue(state_, -1);
  lua_getinfo(state_, ">S", &info);
  if (info.short_src != path) chunknames_.emplace_back(info.short_src, path);
}

void LuaSandbox::enter() const {
  if (std::this_thread::get_id() != forbidden_thread_.load(std::memory_order_relaxed)) return;
  forbidden_uses_.fetch_add(1, std::memory_order_relaxed);
  throw ScenarioError("Lua was called on the real-time loop thread, where it may not run "
                      "(scripting/README.md \"Threads\")");
}

void LuaSandbox::call(int nargs, int nresults, Budget budget) {
  enter();
  ensure_stack(state_, 1);
  const int function = lua_gettop(state_) - nargs;
  lua_pushcfunction(state_, message_handler);
  lua_insert(state_, function);
  start_budget(budget);
  const int status = lua_pcall(state_, nargs, nresults, function);
  lua_remove(state_, function);
  if (status != LUA_OK) throw_error(status);
}

void LuaSandbox::protect(CFunction fn, void* userdata, int nargs, int nresults) {
  enter();
  ensure_stack(state_, 2);
  lua_pushcfunction(state_, fn);
  lua_pushlightuserdata(state_, userdata);
  lua_rotate(state_, -(nargs + 2), 2);
  start_budget(Budget::kCall);
  const int status = lua_pcall(state_, nargs + 1, nresults, 0);
  if (status != LUA_OK) throw_error(status);
}

std::vector<std::string> LuaSandbox::run(std::string_view source, const std::string& path,
                                         Budget budget) {
  const int top = lua_gettop(state_);
  load(source, path);
  call(0, LUA_MULTRET, budget);
  std::vector<std::string> results;
  for (int i = top + 1; i <= lua_gettop(state_); ++i) {
    results.push_back(detail::describe_value(state_, i));
  }
  lua_settop(state_, top);
  return results;
}

// Pops the error object and throws it as a ScenarioError.
void LuaSandbox::throw_error(int status) {
  std::string message;
  if (lua_type(state_, -1) == LUA_TSTRING) {
    std::size_t length = 0;
    const char* text = lua_tolstring(state_, -1, &length);
    message.assign(text, length);
  } else {
    message = std::string("(error object is a ") + luaL_typename(state_, -1) + " value)";
  }
  lua_pop(state_, 1);
  if (memory_limit_hit_) {
    const std::string limit =
        "memory limit of " + std::to_string(limits_.memory_mib) + " MiB exceeded";
    const std::string lua_words = "not enough memory";
    const std::size_t at = message.find(lua_words);
    // A memory error has no traceback (Lua does not call the handler for it); an error in
    // the handler is, with the limit hit, the traceback failing to allocate; a script that
    // caught "not enough memory" and raised it again keeps its file:line.
    if (status == LUA_ERRMEM || status == LUA_ERRERR) {
      message = limit;
    } else if (at != std::string::npos) {
      message.replace(at, lua_words.size(), limit);
    }
  } else if (status == LUA_ERRMEM) {
    message = "out of memory";
  }
  throw ScenarioError(expand_chunknames(std::move(message)));
}

std::string LuaSandbox::expand_chunknames(std::string message) const {
  for (const auto& [abbreviated, full] : chunknames_) {
    for (std::size_t at = message.find(abbreviated); at != std::string::npos;
         at = message.find(abbreviated, at + full.size())) {
      message.replace(at, abbreviated.size(), full);
    }
  }
  return message;
}

}  // namespace graspsim::scripting
