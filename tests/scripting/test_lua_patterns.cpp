// The sandbox's charged pattern functions, string.rep and table.move (scripting/src/lua_patterns):
// the same results and errors as Lua's own library, and a budget that stops them.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <lua.hpp>

#include "graspsim/scripting/lua_sandbox.hpp"
#include "lua_patterns.hpp"
#include "scenario_files.hpp"

using Catch::Matchers::Contains;
using graspsim::scripting::Budget;
using graspsim::scripting::LuaSandbox;
using graspsim::scripting::SandboxLimits;
using scripting_test::error_of;

namespace {

// A Lua script that draws patterns, subjects and replacements from math.random (seeded, so both
// states draw the same ones) and returns every result and error of string.find (with and without
// init and plain), string.match, string.gmatch and string.gsub (string, table and function
// replacements, with and without a count) as one string.
constexpr const char* kDifferential = R"lua(
local seed, cases, longest = ...
math.randomseed(seed)
local items = {"a", "b", "x", ".", "%a", "%d", "%s", "%w", "%p", "%A", "%S", "%%", "%.", "%x", "%u", "%l", "%c", "%g",
  "[ab]", "[^a]", "[a-c]", "[%a_]", "[]]", "[^%s]", "[a-]", "[%]", "[", "%b()", "%bab", "%b", "%f[%a]", "%f[%A]",
  "%f", "%fa", "()", "(", ")", "(a)", "(.-)", "%1", "%2", "%0", "%9", "$", "^", "-", "*", "+", "?", "%", "%z", "\0"}
local quantifiers = {"", "", "", "*", "+", "-", "?"}
local alphabet = {"a", "b", "x", "1", "(", ")", " ", "_", ".", "%", "\0", "A", "]", "\n"}
local function pattern()
  local t = {}
  if math.random() < 0.2 then t[#t + 1] = "^" end
  for _ = 1, math.random(0, 5) do
    t[#t + 1] = items[math.random(#items)]
    t[#t + 1] = quantifiers[math.random(#quantifiers)]
  end
  if math.random() < 0.15 then t[#t + 1] = "$" end
  return table.concat(t)
end
local function subject(n)
  local t = {}
  for i = 1, n do t[i] = alphabet[math.random(#alphabet)] end
  return table.concat(t)
end
local replacements = {"<%0>", "%1", "%%", "[%2]", "x", "%z", "", "%", 7,
  {a = "A", b = false, x = 1, ["1"] = "one"},
  function(c, d) return c and (tostring(c) .. tostring(d)) end,
  function() return {} end, function() return nil end, function() return false end}
local function show(ok, ...)
  local out = {ok and "ok" or "error"}
  for i = 1, select("#", ...) do out[#out + 1] = tostring((select(i, ...))) end
  return table.concat(out, ",")
end
local function all(s, p)
  local t = {}
  for a, b, c in string.gmatch(s, p, math.random(-3, 15)) do
    t[#t + 1] = tostring(a) .. "/" .. tostring(b) .. "/" .. tostring(c)
    if #t > 40 then break end
  end
  return table.concat(t, ";")
end
local out = {}
for _ = 1, cases do
  local s, p = subject(math.random(0, longest)), pattern()
  local r = replacements[math.random(#replacements)]
  out[#out + 1] = table.concat({
    show(pcall(string.find, s, p)),
    show(pcall(string.find, s, p, math.random(-5, 20))),
    show(pcall(string.find, s, p, math.random(-5, 20), true)),
    show(pcall(string.match, s, p)),
    show(pcall(string.match, s, p, math.random(-5, 20))),
    show(pcall(all, s, p)),
    show(pcall(string.gsub, s, p, r)),
    show(pcall(string.gsub, s, p, r, math.random(-1, 3))),
  }, "|")
end
return table.concat(out, "\n")
)lua";

// The script run by Lua's own library (a plain state with every library open).
std::string run_in_lua(const std::string& script, const std::string& args) {
  lua_State* L = luaL_newstate();
  luaL_openlibs(L);
  const std::string source = "return (function(...) " + script + " end)(" + args + ")";
  std::string out;
  if (luaL_loadbufferx(L, source.data(), source.size(), "@patterns.lua", "t") != LUA_OK ||
      lua_pcall(L, 0, 1, 0) != LUA_OK) {
    out = std::string("lua failed: ") + lua_tostring(L, -1);
  } else {
    std::size_t n = 0;
    const char* text = lua_tolstring(L, -1, &n);
    out.assign(text, n);
  }
  lua_close(L);
  return out;
}

std::string run_in_sandbox(const std::string& script, const std::string& args) {
  LuaSandbox lua;
  const std::string source = "return (function(...) " + script + " end)(" + args + ")";
  const std::vector<std::string> results = lua.run(source, "patterns.lua");
  REQUIRE(results.size() == 1);
  return results[0];
}

}  // namespace

// The charged functions are Lua's matcher with a step counter: for every pattern the same
// captures, positions, replacements and counts, and the same error for every malformed one.
// 8 calls on each of 30,000 drawn cases (subjects up to 12 characters from 14, so that no
// pattern of up to 5 items backtracks for long in Lua's own library, which has no budget),
// and 300 cases on subjects up to 3000 characters with 2 items, where the steps pass the charge
// interval (kChargeEvery) many times. Exact equality of the texts: both run the same algorithm.
TEST_CASE("the charged pattern functions give Lua's results and errors on generated patterns",
          "[lua_sandbox][patterns]") {
  for (const char* args : {"1, 30000, 12", "2, 300, 3000"}) {
    INFO("seed, cases, longest subject: " << args);
    const std::string ours = run_in_sandbox(kDifferential, args);
    const std::string lua = run_in_lua(kDifferential, args);
    REQUIRE(lua.rfind("lua failed", 0) != 0);
    if (ours != lua) {
      // The first case that differs, for the message.
      std::size_t at = 0;
      while (at < ours.size() && at < lua.size() && ours[at] == lua[at]) ++at;
      const std::size_t line = ours.rfind('\n', at) == std::string::npos ? 0 : ours.rfind('\n', at) + 1;
      FAIL("first difference at byte " << at << ":\n ours: " << ours.substr(line, 300) << "\n  lua: "
                                        << lua.substr(line, 300));
    }
    // Not vacuous: matches, captures, replacements and errors all occurred.
    CHECK(ours.find("ok,1,") != std::string::npos);
    CHECK(ours.find("error,malformed pattern") != std::string::npos);
    CHECK(ours.find("invalid capture index") != std::string::npos);
  }
  // string.rep and table.move, including their argument errors.
  const std::string more = R"lua(
    local function show(ok, ...) local out = {ok and "ok" or "error"}
      for i = 1, select("#", ...) do local v = select(i, ...) out[#out + 1] = type(v) == "table" and table.concat(v, " ") or tostring(v) end
      return table.concat(out, ",") end
    return table.concat({
      show(pcall(string.rep, "ab", 3, "-")), show(pcall(string.rep, "ab", 0)), show(pcall(string.rep, "x", -2)),
      show(pcall(string.rep, "ab", 2^31)), show(pcall(string.rep, {}, 2)), show(pcall(string.rep, "a", 1.5)),
      show(pcall(table.move, {1, 2, 3}, 1, 3, 2)), show(pcall(table.move, {1, 2, 3}, 2, 3, 1)),
      show(pcall(table.move, {1, 2, 3}, 1, 3, 1, {9})), show(pcall(table.move, {1}, 2, 1, 1)),
      show(pcall(table.move, nil, 1, 2, 1)), show(pcall(table.move, {}, 1, 2)),
      show(pcall(table.move, {}, math.mininteger, 0, 1)), show(pcall(table.move, {}, 1, 3, math.maxinteger))}, "|")
  )lua";
  CHECK(run_in_sandbox(more, "") == run_in_lua(more, ""));
}

// The budget law. ("a"):rep(n):find(".-b") fails at each of its n + 1 start positions i after
// m + 2 steps (m = n - i characters left: one call of match for '.-', m + 1 for 'b', one at each
// length the lazy '.-' tries), n (n + 1) / 2 + 2 (n + 1) steps in all; string.rep charges n. The
// few VM instructions around them stay under the hook's interval, so they count 0. With budget B
// the load stops exactly when T(n) = n (n + 1) / 2 + 3 n + 2 > B: swept over three budgets, the
// largest n with T(n) <= B runs and n + 1 stops, with the budget's message naming the function.
TEST_CASE("a pattern's steps are charged to the instruction budget: the load stops exactly when "
          "they exceed it", "[lua_sandbox][patterns][law]") {
  const auto steps = [](long long n) { return n * (n + 1) / 2 + 3 * n + 2; };
  for (long long budget : {100'000LL, 1'000'000LL, 4'000'000LL}) {
    long long n = 0;
    while (steps(n + 1) <= budget) ++n;
    INFO("budget " << budget << ", n = " << n << " (" << steps(n) << " steps), n + 1: " << steps(n + 1));
    SandboxLimits limits;
    limits.load_instructions = budget;
    LuaSandbox lua(limits);
    const std::string code = "return (('a'):rep(...)):find('.-b')";
    CHECK(lua.run("return (function(...) " + code + " end)(" + std::to_string(n) + ")", "fits.lua") ==
          std::vector<std::string>{"nil"});
    CHECK_THAT(error_of([&] { lua.run("return (function(...) " + code + " end)(" + std::to_string(n + 1) + ")", "over.lua"); }),
               Contains("over.lua:1: instruction budget of " + std::to_string(budget) +
                        " instructions exceeded in string.find: its pattern backtracks too much for this subject"));
  }
}

// A pattern (`.-` x 8 before a "b" over 20000 a's) that backtracks 20000^8 / 8! times in Lua's own
// library (for ever), stops at the default budgets: at load (2e8 steps, about 1.2 s measured) and
// in a later call (2e7), as does a pcall that catches the error and tries again (the hook then
// fires at every instruction). string.rep("", 1e15) and table.move over 1e15 elements, which loop
// in C without allocating, stop before they start.
TEST_CASE("a backtracking pattern, string.rep and table.move stop at the budget",
          "[lua_sandbox][patterns]") {
  LuaSandbox lua;
  const std::string pattern = "local r = string.rep('a', 20000):find(string.rep('.-', 8) .. 'b')";
  CHECK_THAT(error_of([&] { lua.run(pattern, "load.lua"); }),
             Contains("load.lua:1: instruction budget of 200000000 instructions exceeded in string.find"));
  CHECK_THAT(error_of([&] { lua.run(pattern, "call.lua", Budget::kCall); }),
             Contains("call.lua:1: instruction budget of 20000000 instructions exceeded in string.find"));
  CHECK_THAT(error_of([&] {
               lua.run("for i = 1, 3 do pcall(string.find, string.rep('a', 20000), string.rep('.-', 8) .. 'b') end",
                       "again.lua", Budget::kCall);
             }),
             Contains("instruction budget of 20000000 instructions exceeded"));
  CHECK_THAT(error_of([&] { lua.run("local s = string.rep('', 1e15)", "rep.lua"); }),
             Contains("rep.lua:1: instruction budget of 200000000 instructions exceeded in string.rep"));
  CHECK_THAT(error_of([&] { lua.run("local t = table.move({}, 1, 1e15, 1)", "move.lua"); }),
             Contains("move.lua:1: instruction budget of 200000000 instructions exceeded in table.move"));
  // gsub and gmatch are charged too, and a replacement function's own work adds to the same budget.
  CHECK_THAT(error_of([&] { lua.run("string.rep('a', 20000):gsub(string.rep('.-', 8) .. 'b', '')", "gsub.lua", Budget::kCall); }),
             Contains("exceeded in string.gsub"));
  CHECK_THAT(error_of([&] {
               lua.run("for x in string.rep('a', 20000):gmatch(string.rep('.-', 8) .. 'b') do end", "gmatch.lua", Budget::kCall);
             }),
             Contains("exceeded in string.gmatch"));
  // The state is usable afterwards, with a fresh budget.
  CHECK(lua.run("return ('heavy_hold'):match('^(%a+)_')", "after.lua") == std::vector<std::string>{"heavy"});
}
