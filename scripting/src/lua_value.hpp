// Lua values copied out of the state (tables included) and values given with --set, so that a
// scenario table can be checked, overridden and converted in plain C++, where throwing is safe.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace graspsim::scripting::detail {

// A table key: an integer index or a string name (the only keys a scenario table may have).
struct LuaKey {
  bool is_index = false;
  std::int64_t index = 0;   // when is_index
  std::string name;         // otherwise

  static LuaKey at(std::int64_t i) { return LuaKey{true, i, {}}; }
  static LuaKey named(std::string n) { return LuaKey{false, 0, std::move(n)}; }
  std::string str() const { return is_index ? std::to_string(index) : name; }
};
// Indices first, ascending, then names in byte order: a fixed order whatever pairs() does.
bool operator<(const LuaKey& a, const LuaKey& b);
bool operator==(const LuaKey& a, const LuaKey& b);

struct LuaValue {
  enum class Type { kNil, kBoolean, kInteger, kNumber, kString, kTable, kFunction, kOther };
  struct Entry;

  Type type = Type::kNil;
  bool boolean = false;        // kBoolean
  std::int64_t integer = 0;    // kInteger
  double number = 0.0;         // kInteger and kNumber: the value as a double
  std::string text;            // kString: the bytes; kOther: Lua's name of the type
  int ref = 0;                 // kFunction: registry reference (0 when none was taken)
  std::vector<Entry> entries;  // kTable: sorted by key, keys unique

  bool is_number() const { return type == Type::kInteger || type == Type::kNumber; }
  bool is_table() const { return type == Type::kTable; }
  // Lua's name of the type: "nil", "boolean", "number", "string", "table", "function", ...
  std::string type_name() const;
  const LuaValue* find(const LuaKey& key) const;
  LuaValue* find(const LuaKey& key);
  const LuaValue* find(std::string_view name) const { return find(LuaKey::named(std::string(name))); }
  // Sets (or, for kNil, removes) the entry with this key, keeping the entries sorted.
  void set(const LuaKey& key, LuaValue value);
  // n when the keys are exactly 1..n (n = 0 for an empty table), else -1.
  std::int64_t array_length() const;
};
struct LuaValue::Entry {
  LuaKey key;
  LuaValue value;
};

// A value given on the command line as --set path=value.
struct SetValue {
  enum class Type { kNil, kBoolean, kInteger, kNumber, kString, kArray };
  Type type = Type::kNil;
  bool boolean = false;            // kBoolean
  std::int64_t integer = 0;        // kInteger
  double number = 0.0;             // kInteger and kNumber
  std::string text;                // the text as given (kString: the string)
  std::vector<SetValue> elements;  // kArray: numbers

  // "true"/"false" -> boolean, "nil" -> nil (removes a field), a number -> number,
  // "0,0,0.1" -> array of numbers, anything else -> string.
  static SetValue parse(const std::string& text);
  std::string type_name() const;   // "nil", "boolean", "number", "string", "array"
  LuaValue to_lua_value() const;
};

}  // namespace graspsim::scripting::detail
