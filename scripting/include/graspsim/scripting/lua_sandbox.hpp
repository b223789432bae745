// A Lua 5.4 state for scenario code (Redis's recipe): an allow-list of libraries, locked globals,
// a memory limit, an instruction budget per call and a seeded math.random. Every Lua error comes
// out as a ScenarioError after lua_pcall has returned: no C++ exception ever crosses a Lua frame,
// and no Lua error (a longjmp) ever crosses a C++ frame that owns objects with destructors.
//
// The header does not include lua.h: code that works on the stack (scripting/src) includes it.
// One state, one thread: nothing here may be used from two threads at once.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <thread>
#include <string_view>
#include <utility>
#include <vector>

#include "graspsim/scripting/error.hpp"

struct lua_State;
struct lua_Debug;

namespace graspsim::scripting {

struct SandboxLimits {
  std::size_t memory_mib = 256;                  // MiB: every allocation of the state together
  std::int64_t load_instructions = 200'000'000;  // VM instructions to run the scenario file
  std::int64_t call_instructions = 20'000'000;   // VM instructions per later call (trajectory, check)
};

// Which instruction budget a call runs under.
enum class Budget { kLoad, kCall };

class LuaSandbox {
 public:
  using CFunction = int (*)(lua_State*);   // the same type as lua_CFunction

  // Opens base, table, string, math, utf8 and coroutine (without dofile, loadfile, load,
  // require, string.dump); print writes "[lua] ..." lines to stderr; math.random is seeded
  // with 0. Globals are not locked yet: register extra ones, then call lock_globals().
  explicit LuaSandbox(const SandboxLimits& limits = {});
  ~LuaSandbox();
  LuaSandbox(const LuaSandbox&) = delete;
  LuaSandbox& operator=(const LuaSandbox&) = delete;

  lua_State* state() const { return state_; }
  const SandboxLimits& limits() const { return limits_; }

  // Sets global `name` to the C closure fn with one upvalue, the light userdata `upvalue`.
  // Only before lock_globals().
  void register_global(const char* name, CFunction fn, void* upvalue);
  // From now on reading an undefined global or assigning a new one is an error.
  void lock_globals();
  // math.randomseed(seed): the same seed gives the same math.random sequence on every run.
  void seed_random(std::int64_t seed);

  // Compiles `source` (text only) as the chunk "@path" and pushes it. Throws ScenarioError with
  // Lua's "path:line: ..." message on a syntax error.
  void load(std::string_view source, const std::string& path);
  // Calls the function below the top `nargs` values, like lua_pcall, under the given instruction
  // budget (the count starts at zero). On success leaves `nresults` results (LUA_MULTRET: all).
  // On error pops everything it was given and throws ScenarioError: the message with a
  // traceback, the budget message or the memory-limit message.
  void call(int nargs, int nresults, Budget budget);
  // Runs the C function fn under lua_pcall, for C code that can raise a Lua error (allocation,
  // raw sets): fn finds `userdata` as a light userdata at index 1 and the top `nargs` values
  // (popped) after it, and leaves `nresults` results. fn must not own C++ objects with
  // destructors. Throws ScenarioError if it fails.
  void protect(CFunction fn, void* userdata, int nargs, int nresults);

  // Loads and runs `source` and returns its results as text (nil, true, 42, 0.5 as %.17g,
  // strings as they are, "<table>" for other types). For tests and tools.
  std::vector<std::string> run(std::string_view source, const std::string& path,
                               Budget budget = Budget::kLoad);

  std::size_t memory_used() const { return used_bytes_; }   // bytes

  // Charges `steps` units of work done in C on behalf of a script (a pattern match's steps,
  // string.rep's and table.move's iterations: scripting/src/lua_patterns.hpp) to the running
  // call's instruction budget, one unit per VM instruction. Once the budget is spent it raises
  // the budget's Lua error in `state` (a longjmp: call it only where the Lua library could raise
  // one) naming `what`; the count hook then fires at every instruction, as for a Lua loop.
  static void charge(lua_State* state, long long steps, const char* what);

  // Thread guard (scripting/README.md "Threads"): while a thread is forbidden (a paced run's
  // real-time loop), every entry into this state from it is refused before the state is touched
  // (enter() throws ScenarioError) and every allocation made on it is counted. Both are one
  // relaxed atomic load and a compare: always on, in Release too. std::thread::id{} lifts it.
  void forbid_thread(std::thread::id id) { forbidden_thread_.store(id, std::memory_order_relaxed); }
  // Throws ScenarioError when called on the forbidden thread (and counts the attempt).
  void enter() const;
  // Entries and allocations refused or seen on a forbidden thread since the state was made.
  std::int64_t forbidden_uses() const { return forbidden_uses_.load(std::memory_order_relaxed); }

 private:
  static void* allocate(void* self, void* block, std::size_t old_size, std::size_t new_size);
  static void count_hook(lua_State* state, lua_Debug* debug);
  void start_budget(Budget budget);
  [[noreturn]] void throw_error(int status);
  std::string expand_chunknames(std::string message) const;

  SandboxLimits limits_;
  lua_State* state_ = nullptr;
  std::size_t used_bytes_ = 0;         // bytes allocated by the state now
  bool memory_limit_hit_ = false;      // an allocation was refused since the last call started
  std::int64_t instructions_ = 0;      // VM instructions counted since the last call started
  std::int64_t budget_ = 0;            // instructions allowed for the current call
  bool hook_every_instruction_ = false;   // the budget ran out: the hook now fires every time
  // Lua shortens long chunk names to "...tail"; messages get the full path back.
  std::vector<std::pair<std::string, std::string>> chunknames_;   // (short, full)
  std::atomic<std::thread::id> forbidden_thread_{};   // std::thread::id{}: none
  mutable std::atomic<std::int64_t> forbidden_uses_{0};
};

}  // namespace graspsim::scripting
