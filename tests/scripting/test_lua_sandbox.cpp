// The Lua sandbox: what scenario code can and cannot reach, and how runaway code is stopped.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include <catch2/catch.hpp>

#include "graspsim/scripting/lua_sandbox.hpp"
#include "scenario_files.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;
using graspsim::scripting::Budget;
using graspsim::scripting::LuaSandbox;
using graspsim::scripting::SandboxLimits;
using scripting_test::error_of;

namespace {

std::unique_ptr<LuaSandbox> locked_sandbox(const SandboxLimits& limits = {}) {
  auto lua = std::make_unique<LuaSandbox>(limits);
  lua->lock_globals();
  return lua;
}

std::string run_one(LuaSandbox& lua, const std::string& code) {
  const std::vector<std::string> results = lua.run(code, "test.lua");
  REQUIRE(results.size() == 1);
  return results[0];
}

}  // namespace

// Redis's allow-list: no files, processes, modules, debug hooks or loading of other code.
TEST_CASE("the sandbox offers no os, io, package, debug, dofile, loadfile, load, require or "
          "string.dump", "[lua_sandbox]") {
  LuaSandbox lua;
  lua.lock_globals();
  for (const char* name : {"os", "io", "package", "debug", "dofile", "loadfile", "load", "require"}) {
    INFO(name);
    CHECK_THAT(error_of([&] { lua.run(std::string("return ") + name, "test.lua"); }),
               Contains(std::string("undefined global '") + name + "'"));
  }
  CHECK(run_one(lua, "return string.dump") == "nil");
  CHECK(run_one(lua, "return ('').dump") == "nil");   // through the string metatable too
  // ... while the allowed libraries are all there.
  CHECK(lua.run("return type(pairs), type(pcall), type(table.concat), type(string.format), "
                "type(math.floor), type(utf8.char), type(coroutine.wrap), type(collectgarbage)",
                "test.lua") ==
        std::vector<std::string>(8, "function"));
}

TEST_CASE("print writes one '[lua] ' line per call to stderr", "[lua_sandbox]") {
  LuaSandbox lua;
  std::FILE* capture = std::tmpfile();
  REQUIRE(capture != nullptr);
  std::fflush(stderr);
  const int saved = dup(fileno(stderr));
  dup2(fileno(capture), fileno(stderr));
  lua.run("print('hello', 42, nil, true)", "test.lua");
  std::fflush(stderr);
  dup2(saved, fileno(stderr));
  close(saved);
  std::rewind(capture);
  char buffer[256] = {};
  const std::size_t n = std::fread(buffer, 1, sizeof buffer - 1, capture);
  std::fclose(capture);
  CHECK(std::string(buffer, n) == "[lua] hello\t42\tnil\ttrue\n");
}

// The count hook fires every 1000 instructions and raises once the budget is spent; after that
// it fires on every instruction, so even a loop that catches the error with pcall stops.
// The budget is counted in Lua instructions, not time: that it stops at all (with the budget's
// message, not at ctest's timeout) is the law; how fast is the machine's business.
TEST_CASE("an endless loop stops with the instruction-budget message", "[lua_sandbox]") {
  SandboxLimits limits;
  limits.load_instructions = 5'000'000;
  const auto sandbox = locked_sandbox(limits);
  LuaSandbox& lua = *sandbox;
  CHECK_THAT(error_of([&] { lua.run("local n = 0\nwhile true do n = n + 1 end", "loop.lua"); }),
             StartsWith("loop.lua:2: instruction budget of 5000000 instructions exceeded "
                        "(an endless loop?)"));
  CHECK_THAT(error_of([&] {
               lua.run("while true do pcall(function() while true do end end) end", "sly.lua");
             }),
             Contains("instruction budget of 5000000 instructions exceeded"));
  CHECK_THAT(error_of([&] { lua.run("coroutine.wrap(function() while true do end end)()", "co.lua"); }),
             Contains("instruction budget of 5000000 instructions exceeded"));
  // Each call gets a fresh budget, and the later-call budget is the default 2e7.
  CHECK(run_one(lua, "local n = 0 for i = 1, 1000000 do n = n + i end return n") == "500000500000");
  CHECK_THAT(error_of([&] { lua.run("while true do end", "call.lua", Budget::kCall); }),
             Contains("instruction budget of 20000000 instructions exceeded"));
}

TEST_CASE("a memory bomb stops with the memory-limit message and the state stays usable",
          "[lua_sandbox]") {
  const auto sandbox = locked_sandbox();   // the default limit, 256 MiB
  LuaSandbox& lua = *sandbox;
  CHECK(error_of([&] {
          lua.run("local s = string.rep('x', 1 << 20) while true do s = s .. s end", "bomb.lua");
        }) == "memory limit of 256 MiB exceeded");
  CHECK(lua.memory_used() < (std::size_t{256} << 20));
  CHECK(run_one(lua, "return 1 + 1") == "2");
  // A bomb of small tables, against a small limit; caught in pcall and raised again, it keeps
  // its file:line.
  SandboxLimits small;
  small.memory_mib = 8;
  const auto tiny_sandbox = locked_sandbox(small);
  LuaSandbox& tiny = *tiny_sandbox;
  CHECK_THAT(error_of([&] {
               tiny.run("local t = {}\nlocal ok, e = pcall(function() for i = 1, 1e9 do t[i] = {i} end end)\n"
                        "t = nil\nerror(e)", "tables.lua");
             }),
             StartsWith("tables.lua:4: memory limit of 8 MiB exceeded"));
}

// Lua 5.4 seeds math.random from the clock and an address unless told otherwise.
TEST_CASE("math.random gives the same sequence for the same seed and another for another seed",
          "[lua_sandbox]") {
  const auto sequence = [](std::int64_t seed) {
    LuaSandbox lua;
    lua.seed_random(seed);
    return lua.run("return math.random(), math.random(), math.random(1, 1000000)", "random.lua");
  };
  CHECK(sequence(1) == sequence(1));
  CHECK(sequence(1) != sequence(2));
  CHECK(LuaSandbox().run("return math.random()", "a.lua") ==
        LuaSandbox().run("return math.random()", "b.lua"));   // seed 0 when none is given
  LuaSandbox lua;
  CHECK_THAT(error_of([&] { lua.run("math.randomseed()", "reseed.lua"); }),
             Contains("math.randomseed needs a seed"));
  CHECK(lua.run("math.randomseed(5) return math.random()", "reseed.lua")[0] == sequence(5)[0]);
}

TEST_CASE("globals are strict once locked: reading an undefined one or assigning a new one fails",
          "[lua_sandbox]") {
  LuaSandbox lua;
  int marker = 0;
  lua.register_global("answer", [](lua_State*) { return 0; }, &marker);
  lua.lock_globals();
  CHECK_THAT(error_of([&] { lua.run("local a = 1\nreturn undefined_thing", "strict.lua"); }),
             StartsWith("strict.lua:2: undefined global 'undefined_thing'"));
  CHECK_THAT(error_of([&] { lua.run("x = 1", "strict.lua"); }),
             StartsWith("strict.lua:1: assignment to undefined global 'x' (use local)"));
  CHECK(run_one(lua, "local x = 1 return x") == "1");
  CHECK(run_one(lua, "return type(answer)") == "function");   // registered before locking
  CHECK_THAT(error_of([&] { lua.run("setmetatable(_G, nil)", "strict.lua"); }),
             Contains("cannot change a protected metatable"));
}

TEST_CASE("runtime errors carry file:line and a traceback", "[lua_sandbox]") {
  const auto sandbox = locked_sandbox();
  LuaSandbox& lua = *sandbox;
  const std::string message = error_of([&] {
    lua.run("local function f()\n  error('boom')\nend\nf()", "trace.lua");
  });
  CHECK_THAT(message, StartsWith("trace.lua:2: boom\nstack traceback:"));
  CHECK_THAT(message, Contains("trace.lua:4: in main chunk"));
  CHECK_THAT(error_of([&] { lua.run("error({})", "trace.lua"); }),
             StartsWith("(error object is a table value)"));
}

TEST_CASE("only text chunks load, and syntax errors give Lua's path:line message", "[lua_sandbox]") {
  LuaSandbox lua;
  CHECK_THAT(error_of([&] { lua.run(std::string("\x1bLua\x54\x00", 6), "binary.lua"); }),
             Contains("attempt to load a binary chunk (mode is 't')"));
  CHECK_THAT(error_of([&] { lua.run("return {\n  a = 1\n  b = 2\n}", "syntax.lua"); }),
             StartsWith("syntax.lua:3: '}' expected (to close '{' at line 1) near 'b'"));
}

// Lua shortens chunk names longer than 59 characters to "...tail"; messages give the full path.
TEST_CASE("messages name long scenario paths in full", "[lua_sandbox]") {
  const auto sandbox = locked_sandbox();
  LuaSandbox& lua = *sandbox;
  const std::string path = "some/deeply/nested/directory/with/a/very/long/name/of/a/scenario_file.lua";
  REQUIRE(path.size() > 60);
  const std::string message = error_of([&] { lua.run("\nerror('boom')", path); });
  CHECK_THAT(message, StartsWith(path + ":2: boom"));
  CHECK_THAT(message, Contains(path + ":2: in main chunk"));
}

// Lua runs finalizers with hooks off, where no budget could stop them; a metatable with __gc is
// refused when it is set (a __gc added later is never called: Lua marks objects only then).
TEST_CASE("__gc metamethods are refused, so no finalizer can escape the budget", "[lua_sandbox]") {
  const auto sandbox = locked_sandbox();
  LuaSandbox& lua = *sandbox;
  CHECK_THAT(error_of([&] {
               lua.run("setmetatable({}, {__gc = function() while true do end end})", "gc.lua");
             }),
             StartsWith("gc.lua:1: __gc metamethods are not allowed in scenarios"));
  CHECK(run_one(lua, "local mt = {} local t = setmetatable({}, mt) "
                     "mt.__gc = function() while true do end end t = nil collectgarbage() "
                     "return getmetatable(setmetatable({}, {__index = {a = 1}})).__index.a") == "1");
}
