// Plain C++ copies of Lua values, and the parsing of --set values.
#include "lua_value.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace graspsim::scripting::detail {

bool operator<(const LuaKey& a, const LuaKey& b) {
  if (a.is_index != b.is_index) return a.is_index;
  return a.is_index ? a.index < b.index : a.name < b.name;
}

bool operator==(const LuaKey& a, const LuaKey& b) {
  return a.is_index == b.is_index && (a.is_index ? a.index == b.index : a.name == b.name);
}

std::string LuaValue::type_name() const {
  switch (type) {
    case Type::kNil: return "nil";
    case Type::kBoolean: return "boolean";
    case Type::kInteger:
    case Type::kNumber: return "number";
    case Type::kString: return "string";
    case Type::kTable: return "table";
    case Type::kFunction: return "function";
    case Type::kOther: return text;
  }
  return "?";
}

const LuaValue* LuaValue::find(const LuaKey& key) const {
  const auto it = std::lower_bound(entries.begin(), entries.end(), key,
                                   [](const Entry& e, const LuaKey& k) { return e.key < k; });
  return it != entries.end() && it->key == key ? &it->value : nullptr;
}

LuaValue* LuaValue::find(const LuaKey& key) {
  return const_cast<LuaValue*>(static_cast<const LuaValue*>(this)->find(key));
}

void LuaValue::set(const LuaKey& key, LuaValue value) {
  const auto it = std::lower_bound(entries.begin(), entries.end(), key,
                                   [](const Entry& e, const LuaKey& k) { return e.key < k; });
  const bool present = it != entries.end() && it->key == key;
  if (value.type == Type::kNil) {
    if (present) entries.erase(it);
  } else if (present) {
    it->value = std::move(value);
  } else {
    entries.insert(it, Entry{key, std::move(value)});
  }
}

std::int64_t LuaValue::array_length() const {
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const LuaKey& key = entries[i].key;
    if (!key.is_index || key.index != static_cast<std::int64_t>(i) + 1) return -1;
  }
  return static_cast<std::int64_t>(entries.size());
}

namespace {

// A decimal number as --set accepts it: optional sign, digits, '.', exponent. No inf or nan.
bool parse_number(const std::string& text, SetValue& out) {
  if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos) return false;
  const char* begin = text.data();
  const char* end = begin + text.size();
  if (*begin == '+') ++begin;
  if (begin == end || *begin == '+') return false;
  std::int64_t integer = 0;
  auto [int_end, int_error] = std::from_chars(begin, end, integer);
  if (int_error == std::errc() && int_end == end) {
    out.type = SetValue::Type::kInteger;
    out.integer = integer;
    out.number = static_cast<double>(integer);
    return true;
  }
  double number = 0.0;
  auto [end_number, error] = std::from_chars(begin, end, number);
  if (error != std::errc() || end_number != end || !std::isfinite(number)) return false;
  out.type = SetValue::Type::kNumber;
  out.number = number;
  return true;
}

}  // namespace

SetValue SetValue::parse(const std::string& text) {
  SetValue value;
  value.text = text;
  if (text == "true" || text == "false") {
    value.type = Type::kBoolean;
    value.boolean = text == "true";
    return value;
  }
  if (text == "nil") return value;
  if (parse_number(text, value)) return value;
  if (text.find(',') != std::string::npos) {
    std::vector<SetValue> elements;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = std::min(text.find(',', start), text.size());
      SetValue element;
      element.text = text.substr(start, comma - start);
      if (!parse_number(element.text, element)) break;
      elements.push_back(std::move(element));
      if (comma == text.size()) {
        value.type = Type::kArray;
        value.elements = std::move(elements);
        return value;
      }
      start = comma + 1;
    }
  }
  value.type = Type::kString;
  return value;
}

std::string SetValue::type_name() const {
  switch (type) {
    case Type::kNil: return "nil";
    case Type::kBoolean: return "boolean";
    case Type::kInteger:
    case Type::kNumber: return "number";
    case Type::kString: return "string";
    case Type::kArray: return "array";
  }
  return "?";
}

LuaValue SetValue::to_lua_value() const {
  LuaValue value;
  switch (type) {
    case Type::kNil: break;
    case Type::kBoolean:
      value.type = LuaValue::Type::kBoolean;
      value.boolean = boolean;
      break;
    case Type::kInteger:
      value.type = LuaValue::Type::kInteger;
      value.integer = integer;
      value.number = number;
      break;
    case Type::kNumber:
      value.type = LuaValue::Type::kNumber;
      value.number = number;
      break;
    case Type::kString:
      value.type = LuaValue::Type::kString;
      value.text = text;
      break;
    case Type::kArray:
      value.type = LuaValue::Type::kTable;
      for (std::size_t i = 0; i < elements.size(); ++i) {
        value.entries.push_back({LuaKey::at(static_cast<std::int64_t>(i) + 1),
                                 elements[i].to_lua_value()});
      }
      break;
  }
  return value;
}

}  // namespace graspsim::scripting::detail
