// Charged versions of Lua's pattern functions, string.rep and table.move (see lua_patterns.hpp).
//
// The matcher is Lua 5.4's (lstrlib.c: match, single_match, max_expand, min_expand, captures,
// %b, %f, anchors, find's plain search, gmatch's and gsub's empty-match rule), written again
// here step for step so that every result and every error message is the standard library's;
// tests/scripting/test_lua_patterns.cpp compares the two on thousands of generated patterns.
// The only addition is the step counter. Lua is
//   Copyright (C) 1994-2022 Lua.org, PUC-Rio.
//   Permission is hereby granted, free of charge, to any person obtaining a copy of this
//   software and associated documentation files (the "Software"), to deal in the Software
//   without restriction, including without limitation the rights to use, copy, modify, merge,
//   publish, distribute, sublicense, and/or sell copies of the Software, and to permit persons to
//   whom the Software is furnished to do so, subject to the following conditions: The above
//   copyright notice and this permission notice shall be included in all copies or substantial
//   portions of the Software. THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND.
//
// Lua errors (longjmp) are raised from these functions, so no frame here owns an object with a
// destructor: plain structs and the Lua stack only.
#include "lua_patterns.hpp"

#include <cctype>
#include <cstddef>
#include <cstring>

#include <lua.hpp>

#include "graspsim/scripting/lua_sandbox.hpp"

namespace graspsim::scripting::detail {
namespace {

constexpr int kMaxCaptures = 32;         // LUA_MAXCAPTURES
constexpr int kMaxMatchDepth = 200;      // MAXCCALLS: recursion of the matcher
constexpr char kEscape = '%';
constexpr const char* kSpecials = "^$*+?.([%-";
constexpr std::ptrdiff_t kCaptureUnfinished = -1;
constexpr std::ptrdiff_t kCapturePosition = -2;

// What the budget's message says ran out (LuaSandbox::charge).
constexpr const char* kFindWork = "string.find: its pattern backtracks too much for this subject";
constexpr const char* kMatchWork = "string.match: its pattern backtracks too much for this subject";
constexpr const char* kGmatchWork = "string.gmatch: its pattern backtracks too much for this subject";
constexpr const char* kGsubWork = "string.gsub: its pattern backtracks too much for this subject";

unsigned char uchar(char c) { return static_cast<unsigned char>(c); }

struct MatchState {
  const char* src_init;   // the subject
  const char* src_end;    // its end
  const char* p_end;      // the pattern's end
  lua_State* L;
  const char* what;       // the function, for the budget's message
  int matchdepth;         // recursion left
  int level;              // captures open or closed
  struct {
    const char* init;
    std::ptrdiff_t len;
  } capture[kMaxCaptures];
  long steps;             // steps not yet charged
};

// One step of work: a call of match(), or one character tested by a loop.
void step(MatchState* ms) {
  if (++ms->steps >= kChargeEvery) {
    const long steps = ms->steps;
    ms->steps = 0;
    LuaSandbox::charge(ms->L, steps, ms->what);
  }
}

// What is left uncharged when the function returns.
void settle(MatchState* ms) {
  const long steps = ms->steps;
  ms->steps = 0;
  if (steps > 0) LuaSandbox::charge(ms->L, steps, ms->what);
}

const char* match(MatchState* ms, const char* s, const char* p);

int check_capture(MatchState* ms, int l) {
  l -= '1';
  if (l < 0 || l >= ms->level || ms->capture[l].len == kCaptureUnfinished)
    return luaL_error(ms->L, "invalid capture index %%%d", l + 1);
  return l;
}

int capture_to_close(MatchState* ms) {
  int level = ms->level;
  for (level--; level >= 0; level--)
    if (ms->capture[level].len == kCaptureUnfinished) return level;
  return luaL_error(ms->L, "invalid pattern capture");
}

const char* class_end(MatchState* ms, const char* p) {
  switch (*p++) {
    case kEscape:
      if (p == ms->p_end) luaL_error(ms->L, "malformed pattern (ends with '%%')");
      return p + 1;
    case '[':
      if (*p == '^') p++;
      do {   // look for a ']'
        if (p == ms->p_end) luaL_error(ms->L, "malformed pattern (missing ']')");
        if (*(p++) == kEscape && p < ms->p_end) p++;   // skip escapes (e.g. '%]')
      } while (*p != ']');
      return p + 1;
    default:
      return p;
  }
}

bool match_class(int c, int cl) {
  bool res;
  switch (std::tolower(cl)) {
    case 'a': res = std::isalpha(c); break;
    case 'c': res = std::iscntrl(c); break;
    case 'd': res = std::isdigit(c); break;
    case 'g': res = std::isgraph(c); break;
    case 'l': res = std::islower(c); break;
    case 'p': res = std::ispunct(c); break;
    case 's': res = std::isspace(c); break;
    case 'u': res = std::isupper(c); break;
    case 'w': res = std::isalnum(c); break;
    case 'x': res = std::isxdigit(c); break;
    case 'z': res = (c == 0); break;   // deprecated in Lua, still there
    default: return cl == c;
  }
  if (std::isupper(cl)) res = !res;
  return res;
}

// [...] from p (at '[') to ec (at ']').
bool match_bracket_class(int c, const char* p, const char* ec) {
  bool sig = true;
  if (*(p + 1) == '^') {
    sig = false;
    p++;   // skip the '^'
  }
  while (++p < ec) {
    if (*p == kEscape) {
      p++;
      if (match_class(c, uchar(*p))) return sig;
    } else if (*(p + 1) == '-' && (p + 2 < ec)) {
      p += 2;
      if (uchar(*(p - 2)) <= c && c <= uchar(*p)) return sig;
    } else if (uchar(*p) == c) {
      return sig;
    }
  }
  return !sig;
}

bool single_match(MatchState* ms, const char* s, const char* p, const char* ep) {
  if (s >= ms->src_end) return false;
  const int c = uchar(*s);
  switch (*p) {
    case '.': return true;   // matches any char
    case kEscape: return match_class(c, uchar(*(p + 1)));
    case '[': return match_bracket_class(c, p, ep - 1);
    default: return uchar(*p) == c;
  }
}

const char* match_balance(MatchState* ms, const char* s, const char* p) {
  if (p >= ms->p_end - 1) luaL_error(ms->L, "malformed pattern (missing arguments to '%%b')");
  if (*s != *p) return nullptr;
  const int b = *p;
  const int e = *(p + 1);
  int cont = 1;
  while (++s < ms->src_end) {
    step(ms);
    if (*s == e) {
      if (--cont == 0) return s + 1;
    } else if (*s == b) {
      cont++;
    }
  }
  return nullptr;   // string ends out of balance
}

const char* max_expand(MatchState* ms, const char* s, const char* p, const char* ep) {
  std::ptrdiff_t i = 0;   // counts maximum expand for item
  while (single_match(ms, s + i, p, ep)) {
    step(ms);
    i++;
  }
  // keeps trying to match with the maximum repetitions
  while (i >= 0) {
    const char* res = match(ms, (s + i), ep + 1);
    if (res) return res;
    i--;   // else didn't match; reduce 1 repetition to try again
  }
  return nullptr;
}

const char* min_expand(MatchState* ms, const char* s, const char* p, const char* ep) {
  for (;;) {
    const char* res = match(ms, s, ep + 1);
    if (res != nullptr) return res;
    if (single_match(ms, s, p, ep)) s++;   // try with one more repetition
    else return nullptr;
  }
}

const char* start_capture(MatchState* ms, const char* s, const char* p, std::ptrdiff_t what) {
  const int level = ms->level;
  if (level >= kMaxCaptures) luaL_error(ms->L, "too many captures");
  ms->capture[level].init = s;
  ms->capture[level].len = what;
  ms->level = level + 1;
  const char* res = match(ms, s, p);
  if (res == nullptr) ms->level--;   // match failed: undo capture
  return res;
}

const char* end_capture(MatchState* ms, const char* s, const char* p) {
  const int l = capture_to_close(ms);
  ms->capture[l].len = s - ms->capture[l].init;   // close capture
  const char* res = match(ms, s, p);
  if (res == nullptr) ms->capture[l].len = kCaptureUnfinished;   // match failed: undo capture
  return res;
}

const char* match_capture(MatchState* ms, const char* s, int l) {
  l = check_capture(ms, l);
  const std::size_t len = static_cast<std::size_t>(ms->capture[l].len);
  if (static_cast<std::size_t>(ms->src_end - s) >= len && std::memcmp(ms->capture[l].init, s, len) == 0) return s + len;
  return nullptr;
}

const char* match(MatchState* ms, const char* s, const char* p) {
  if (ms->matchdepth-- == 0) luaL_error(ms->L, "pattern too complex");
  step(ms);
init:   // using goto to optimize tail recursion, as Lua does
  if (p != ms->p_end) {
    switch (*p) {
      case '(':   // start capture
        if (*(p + 1) == ')') s = start_capture(ms, s, p + 2, kCapturePosition);
        else s = start_capture(ms, s, p + 1, kCaptureUnfinished);
        break;
      case ')':   // end capture
        s = end_capture(ms, s, p + 1);
        break;
      case '$':
        if ((p + 1) != ms->p_end) goto dflt;   // not the end of the pattern: a plain '$'
        s = (s == ms->src_end) ? s : nullptr;   // check end of string
        break;
      case kEscape:
        switch (*(p + 1)) {
          case 'b':   // balanced string?
            s = match_balance(ms, s, p + 2);
            if (s != nullptr) {
              p += 4;
              goto init;
            }
            break;
          case 'f': {   // frontier?
            p += 2;
            if (*p != '[') luaL_error(ms->L, "missing '[' after '%%f' in pattern");
            const char* ep = class_end(ms, p);   // points to what is next
            const char previous = (s == ms->src_init) ? '\0' : *(s - 1);
            if (!match_bracket_class(uchar(previous), p, ep - 1) && match_bracket_class(uchar(*s), p, ep - 1)) {
              p = ep;
              goto init;
            }
            s = nullptr;   // match failed
            break;
          }
          case '0': case '1': case '2': case '3': case '4':
          case '5': case '6': case '7': case '8': case '9':   // capture results (%0-%9)?
            s = match_capture(ms, s, uchar(*(p + 1)));
            if (s != nullptr) {
              p += 2;
              goto init;
            }
            break;
          default:
            goto dflt;
        }
        break;
      default:
      dflt: {   // pattern class plus optional suffix
        const char* ep = class_end(ms, p);   // points to optional suffix
        if (!single_match(ms, s, p, ep)) {
          if (*ep == '*' || *ep == '?' || *ep == '-') {   // accept empty?
            p = ep + 1;
            goto init;
          }
          s = nullptr;   // '+' or no suffix: fail
        } else {   // matched once
          switch (*ep) {
            case '?': {
              const char* res = match(ms, s + 1, ep + 1);
              if (res != nullptr) {
                s = res;
              } else {
                p = ep + 1;
                goto init;
              }
              break;
            }
            case '+': s = max_expand(ms, s + 1, p, ep); break;   // 1 or more repetitions
            case '*': s = max_expand(ms, s, p, ep); break;       // 0 or more repetitions
            case '-': s = min_expand(ms, s, p, ep); break;       // 0 or more repetitions (minimum)
            default:   // no suffix
              s++;
              p = ep;
              goto init;
          }
        }
        break;
      }
    }
  }
  ms->matchdepth++;
  return s;
}

std::ptrdiff_t get_onecapture(MatchState* ms, int i, const char* s, const char* e, const char** cap) {
  if (i >= ms->level) {
    if (i != 0) luaL_error(ms->L, "invalid capture index %%%d", i + 1);
    *cap = s;   // the whole match
    return e - s;
  }
  const std::ptrdiff_t capl = ms->capture[i].len;
  *cap = ms->capture[i].init;
  if (capl == kCaptureUnfinished) luaL_error(ms->L, "unfinished capture");
  else if (capl == kCapturePosition) lua_pushinteger(ms->L, (ms->capture[i].init - ms->src_init) + 1);
  return capl;
}

void push_onecapture(MatchState* ms, int i, const char* s, const char* e) {
  const char* cap;
  const std::ptrdiff_t l = get_onecapture(ms, i, s, e, &cap);
  if (l != kCapturePosition) lua_pushlstring(ms->L, cap, static_cast<std::size_t>(l));
  // else the position was already pushed
}

int push_captures(MatchState* ms, const char* s, const char* e) {
  const int nlevels = (ms->level == 0 && s) ? 1 : ms->level;
  luaL_checkstack(ms->L, nlevels, "too many captures");
  for (int i = 0; i < nlevels; i++) push_onecapture(ms, i, s, e);
  return nlevels;   // number of strings pushed
}

// Whether the pattern has no special characters (embedded zeros included).
bool nospecials(const char* p, std::size_t l) {
  std::size_t upto = 0;
  do {
    if (std::strpbrk(p + upto, kSpecials)) return false;   // pattern has a special character
    upto += std::strlen(p + upto) + 1;   // may have more after \0
  } while (upto <= l);
  return true;
}

// find's plain search; every candidate position and every 64 bytes compared is a step.
const char* lmemfind(MatchState* ms, const char* s1, std::size_t l1, const char* s2, std::size_t l2) {
  if (l2 == 0) return s1;   // the empty string is found at once
  if (l2 > l1) return nullptr;
  const char* init;
  l2--;   // the first char is checked by memchr
  l1 = l1 - l2;   // 's2' cannot be found after that
  while (l1 > 0 && (init = static_cast<const char*>(std::memchr(s1, *s2, l1))) != nullptr) {
    ms->steps += static_cast<long>(l2 / 64);
    step(ms);
    init++;   // 1st char is already checked
    if (std::memcmp(init, s2 + 1, l2) == 0) return init - 1;
    l1 -= static_cast<std::size_t>(init - s1);   // correct 'l1' and 's1' to try again
    s1 = init;
  }
  return nullptr;
}

// A relative initial position: negative counts from the end, and is clipped to [1, inf).
std::size_t posrelat_start(lua_Integer pos, std::size_t len) {
  if (pos > 0) return static_cast<std::size_t>(pos);
  if (pos == 0) return 1;
  if (pos < -static_cast<lua_Integer>(len)) return 1;   // clip to 1
  return len + static_cast<std::size_t>(pos) + 1;
}

void prepstate(MatchState* ms, lua_State* L, const char* what, const char* s, std::size_t ls, const char* p,
               std::size_t lp) {
  ms->L = L;
  ms->what = what;
  ms->matchdepth = kMaxMatchDepth;
  ms->src_init = s;
  ms->src_end = s + ls;
  ms->p_end = p + lp;
  ms->level = 0;
  ms->steps = 0;
}

void reprepstate(MatchState* ms) {
  ms->level = 0;
  ms->matchdepth = kMaxMatchDepth;
}

int str_find_aux(lua_State* L, bool find) {
  std::size_t ls, lp;
  const char* s = luaL_checklstring(L, 1, &ls);
  const char* p = luaL_checklstring(L, 2, &lp);
  const std::size_t init = posrelat_start(luaL_optinteger(L, 3, 1), ls) - 1;
  if (init > ls) {   // start after string's end?
    lua_pushnil(L);   // cannot find anything
    return 1;
  }
  MatchState ms;
  prepstate(&ms, L, find ? kFindWork : kMatchWork, s, ls, p, lp);
  // explicit request or no special characters?
  if (find && (lua_toboolean(L, 4) || nospecials(p, lp))) {
    const char* s2 = lmemfind(&ms, s + init, ls - init, p, lp);
    settle(&ms);
    if (s2) {
      lua_pushinteger(L, (s2 - s) + 1);
      lua_pushinteger(L, static_cast<lua_Integer>((s2 - s) + lp));
      return 2;
    }
  } else {
    const char* s1 = s + init;
    const bool anchor = (*p == '^');
    if (anchor) {
      p++;
      lp--;   // skip anchor character
      ms.p_end = p + lp;
    }
    do {
      reprepstate(&ms);
      const char* res = match(&ms, s1, p);
      if (res != nullptr) {
        settle(&ms);
        if (find) {
          lua_pushinteger(L, (s1 - s) + 1);   // start
          lua_pushinteger(L, res - s);        // end
          return push_captures(&ms, nullptr, nullptr) + 2;
        }
        return push_captures(&ms, s1, res);
      }
    } while (s1++ < ms.src_end && !anchor);
    settle(&ms);
  }
  lua_pushnil(L);   // not found
  return 1;
}

int str_find(lua_State* L) { return str_find_aux(L, true); }
int str_match(lua_State* L) { return str_find_aux(L, false); }

// gmatch's state: a full userdata without a metatable, kept as an upvalue of the iterator.
struct GMatchState {
  const char* src;         // current position
  const char* p;           // pattern
  const char* lastmatch;   // end of last match
  MatchState ms;
};

int gmatch_aux(lua_State* L) {
  auto* gm = static_cast<GMatchState*>(lua_touserdata(L, lua_upvalueindex(3)));
  gm->ms.L = L;
  for (const char* src = gm->src; src <= gm->ms.src_end; src++) {
    reprepstate(&gm->ms);
    const char* e = match(&gm->ms, src, gm->p);
    if (e != nullptr && e != gm->lastmatch) {
      gm->src = gm->lastmatch = e;
      settle(&gm->ms);
      return push_captures(&gm->ms, src, e);
    }
  }
  settle(&gm->ms);
  return 0;   // not found
}

int gmatch(lua_State* L) {
  std::size_t ls, lp;
  const char* s = luaL_checklstring(L, 1, &ls);
  const char* p = luaL_checklstring(L, 2, &lp);
  std::size_t init = posrelat_start(luaL_optinteger(L, 3, 1), ls) - 1;
  lua_settop(L, 2);   // keep strings on closure to avoid being collected
  auto* gm = static_cast<GMatchState*>(lua_newuserdatauv(L, sizeof(GMatchState), 0));
  if (init > ls) init = ls + 1;   // start after string's end
  prepstate(&gm->ms, L, kGmatchWork, s, ls, p, lp);
  gm->src = s + init;
  gm->p = p;
  gm->lastmatch = nullptr;
  lua_pushcclosure(L, gmatch_aux, 3);
  return 1;
}

void add_s(MatchState* ms, luaL_Buffer* b, const char* s, const char* e) {
  std::size_t l;
  lua_State* L = ms->L;
  const char* news = lua_tolstring(L, 3, &l);
  const char* p;
  while ((p = static_cast<const char*>(std::memchr(news, kEscape, l))) != nullptr) {
    luaL_addlstring(b, news, static_cast<std::size_t>(p - news));
    p++;   // skip the escape
    if (*p == kEscape) {   // '%%'
      luaL_addchar(b, *p);
    } else if (*p == '0') {   // '%0'
      luaL_addlstring(b, s, static_cast<std::size_t>(e - s));
    } else if (std::isdigit(uchar(*p))) {   // '%n'
      const char* cap;
      const std::ptrdiff_t resl = get_onecapture(ms, *p - '1', s, e, &cap);
      if (resl == kCapturePosition) luaL_addvalue(b);   // add position to accumulated result
      else luaL_addlstring(b, cap, static_cast<std::size_t>(resl));
    } else {
      luaL_error(L, "invalid use of '%c' in replacement string", kEscape);
    }
    l -= static_cast<std::size_t>(p + 1 - news);
    news = p + 1;
  }
  luaL_addlstring(b, news, l);
}

// Adds the replacement of one match; false if the original text was kept.
bool add_value(MatchState* ms, luaL_Buffer* b, const char* s, const char* e, int tr) {
  lua_State* L = ms->L;
  switch (tr) {
    case LUA_TFUNCTION: {   // call the function
      lua_pushvalue(L, 3);
      const int n = push_captures(ms, s, e);
      lua_call(L, n, 1);
      break;
    }
    case LUA_TTABLE: {   // index the table
      push_onecapture(ms, 0, s, e);
      lua_gettable(L, 3);
      break;
    }
    default: {   // LUA_TNUMBER or LUA_TSTRING
      add_s(ms, b, s, e);
      return true;
    }
  }
  if (!lua_toboolean(L, -1)) {   // nil or false?
    lua_pop(L, 1);
    luaL_addlstring(b, s, static_cast<std::size_t>(e - s));   // keep original text
    return false;
  }
  if (!lua_isstring(L, -1)) {
    luaL_error(L, "invalid replacement value (a %s)", luaL_typename(L, -1));
    return false;
  }
  luaL_addvalue(b);   // add result to accumulator
  return true;
}

int str_gsub(lua_State* L) {
  std::size_t srcl, lp;
  const char* src = luaL_checklstring(L, 1, &srcl);   // subject
  const char* p = luaL_checklstring(L, 2, &lp);       // pattern
  const char* lastmatch = nullptr;   // end of last match
  const int tr = lua_type(L, 3);     // replacement type
  const lua_Integer max_s = luaL_optinteger(L, 4, static_cast<lua_Integer>(srcl) + 1);   // max replacements
  const bool anchor = (*p == '^');
  lua_Integer n = 0;   // replacement count
  bool changed = false;   // change in the subject?
  MatchState ms;
  luaL_Buffer b;
  luaL_argexpected(L, tr == LUA_TNUMBER || tr == LUA_TSTRING || tr == LUA_TFUNCTION || tr == LUA_TTABLE, 3,
                   "string/function/table");
  luaL_buffinit(L, &b);
  if (anchor) {
    p++;
    lp--;   // skip anchor character
  }
  prepstate(&ms, L, kGsubWork, src, srcl, p, lp);
  while (n < max_s) {
    reprepstate(&ms);
    const char* e = match(&ms, src, p);
    if (e != nullptr && e != lastmatch) {   // match?
      n++;
      settle(&ms);   // before a replacement function runs under the same budget
      changed = add_value(&ms, &b, src, e, tr) | changed;
      src = lastmatch = e;
    } else if (src < ms.src_end) {   // otherwise, skip one character
      luaL_addchar(&b, *src++);
    } else {
      break;   // end of subject
    }
    if (anchor) break;
  }
  settle(&ms);
  if (!changed) {   // no changes?
    lua_pushvalue(L, 1);   // return original string
  } else {   // something changed
    luaL_addlstring(&b, src, static_cast<std::size_t>(ms.src_end - src));
    luaL_pushresult(&b);   // create and return new string
  }
  lua_pushinteger(L, n);   // number of substitutions
  return 2;
}

// string.rep(s, n [, sep]) and table.move(a1, f, e, t [, a2]) loop n (e - f + 1) times in C
// (string.rep("", 1e15) never ends, and allocates nothing on the way): each iteration is a step,
// charged once the arguments are checked and before the loop starts. Both as in ltablib.c and
// lstrlib.c of Lua 5.4.

int str_rep(lua_State* L) {
  std::size_t l, lsep;
  const char* s = luaL_checklstring(L, 1, &l);
  lua_Integer n = luaL_checkinteger(L, 2);
  const char* sep = luaL_optlstring(L, 3, "", &lsep);
  constexpr std::size_t kMaxSize = 0x7fffffff;   // MAXSIZE: INT_MAX where size_t is wider than int
  if (n <= 0) {
    lua_pushliteral(L, "");
    return 1;
  }
  if (l + lsep < l || l + lsep > kMaxSize / static_cast<std::size_t>(n)) return luaL_error(L, "resulting string too large");
  LuaSandbox::charge(L, n, "string.rep: too many repetitions");
  const std::size_t total = static_cast<std::size_t>(n) * l + static_cast<std::size_t>(n - 1) * lsep;
  luaL_Buffer b;
  char* p = luaL_buffinitsize(L, &b, total);
  while (n-- > 1) {   // first n - 1 copies, each followed by the separator
    std::memcpy(p, s, l);
    p += l;
    if (lsep > 0) {
      std::memcpy(p, sep, lsep);
      p += lsep;
    }
  }
  std::memcpy(p, s, l);   // last copy (not followed by separator)
  luaL_pushresultsize(&b, total);
  return 1;
}

// Table argument `arg`: a table, or anything whose metatable has the metamethods a move needs.
void check_table(lua_State* L, int arg, bool read, bool write) {
  if (lua_type(L, arg) == LUA_TTABLE) return;
  int n = 1;   // values to pop
  const auto has = [&](const char* key) {
    lua_pushstring(L, key);
    ++n;
    return lua_rawget(L, -n) != LUA_TNIL;
  };
  if (lua_getmetatable(L, arg) && (!read || has("__index")) && (!write || has("__newindex"))) {
    lua_pop(L, n);
  } else {
    luaL_checktype(L, arg, LUA_TTABLE);   // raises the error
  }
}

int table_move(lua_State* L) {
  const lua_Integer f = luaL_checkinteger(L, 2);
  const lua_Integer e = luaL_checkinteger(L, 3);
  const lua_Integer t = luaL_checkinteger(L, 4);
  const int tt = !lua_isnoneornil(L, 5) ? 5 : 1;   // destination table
  check_table(L, 1, true, false);
  check_table(L, tt, false, true);
  if (e >= f) {   // otherwise, nothing to move
    luaL_argcheck(L, f > 0 || e < LUA_MAXINTEGER + f, 3, "too many elements to move");
    const lua_Integer n = e - f + 1;   // number of elements to move
    luaL_argcheck(L, t <= LUA_MAXINTEGER - n + 1, 4, "destination wrap around");
    LuaSandbox::charge(L, n, "table.move: too many elements");
    if (t > e || t <= f || (tt != 1 && !lua_compare(L, 1, tt, LUA_OPEQ))) {
      for (lua_Integer i = 0; i < n; i++) {
        lua_geti(L, 1, f + i);
        lua_seti(L, tt, t + i);
      }
    } else {
      for (lua_Integer i = n - 1; i >= 0; i--) {
        lua_geti(L, 1, f + i);
        lua_seti(L, tt, t + i);
      }
    }
  }
  lua_pushvalue(L, tt);   // return destination table
  return 1;
}

}  // namespace

int install_charged_functions(lua_State* L) {
  static const luaL_Reg kString[] = {{"find", str_find}, {"match", str_match}, {"gmatch", gmatch},
                                     {"gsub", str_gsub}, {"rep", str_rep},     {nullptr, nullptr}};
  static const luaL_Reg kTable[] = {{"move", table_move}, {nullptr, nullptr}};
  lua_getglobal(L, LUA_STRLIBNAME);
  luaL_setfuncs(L, kString, 0);
  lua_getglobal(L, LUA_TABLIBNAME);
  luaL_setfuncs(L, kTable, 0);
  lua_pop(L, 2);
  return 0;
}

}  // namespace graspsim::scripting::detail
