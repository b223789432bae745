// --set overrides of scenario values.
#include "overrides.hpp"

#include <algorithm>

#include "messages.hpp"
#include "schema.hpp"

namespace graspsim::scripting::detail {
namespace {

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() <= 15 && s.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

std::vector<Override> parse_overrides(const std::vector<std::string>& sets) {
  std::vector<Override> overrides;
  for (const std::string& text : sets) {
    const std::size_t equals = text.find('=');
    if (equals == std::string::npos || equals == 0) {
      throw ConversionError("--set " + text + ": expected name=value (like objects.box.mass=0.5)");
    }
    Override o;
    o.text = text;
    o.path = text.substr(0, equals);
    o.value = SetValue::parse(text.substr(equals + 1));
    for (std::size_t start = 0;;) {
      const std::size_t dot = std::min(o.path.find('.', start), o.path.size());
      o.segments.push_back(o.path.substr(start, dot - start));
      if (o.segments.back().empty()) {
        throw ConversionError("--set " + text + ": empty name in the path '" + o.path + "'");
      }
      if (dot == o.path.size()) break;
      start = dot + 1;
    }
    overrides.push_back(std::move(o));
  }
  return overrides;
}

std::vector<LuaKey> apply_override(LuaValue& root, const Override& o,
                                   const std::vector<std::string>& params) {
  const auto fail = [&](const std::string& what) -> void {
    throw ConversionError("--set " + o.text + ": " + what);
  };
  std::vector<LuaKey> chain;
  LuaValue* table = &root;
  TableKind kind = TableKind::kRoot;
  std::string where;   // the path so far, for messages
  for (std::size_t i = 0; i < o.segments.size(); ++i) {
    const std::string& segment = o.segments[i];
    if (!table->is_table()) {
      fail("'" + where + "' is " + (table->type == LuaValue::Type::kNil ? "absent" : "a " +
           table->type_name()) + ", not a table");
    }
    LuaKey key;
    if (is_named_array(kind)) {
      // An element by its name (or `what`), else by its index.
      const char* noun = element_noun(kind);
      std::vector<std::string> names;
      for (std::size_t j = 0; j < table->entries.size(); ++j) {
        const std::string name = element_segment(kind, *table, j);
        names.push_back(name);
        if (name == segment && !key.is_index) key = table->entries[j].key;
      }
      if (!key.is_index && all_digits(segment) &&
          table->find(LuaKey::at(std::stoll(segment))) != nullptr) {
        key = LuaKey::at(std::stoll(segment));
      }
      if (!key.is_index) {
        fail(std::string("no ") + noun + " named '" + segment + "' (" + o.segments[0] + ": " +
             (names.empty() ? "none" : join(names)) + ")");
      }
    } else if (kind == TableKind::kWaypoints || kind == TableKind::kVector) {
      if (!all_digits(segment) || table->find(LuaKey::at(std::stoll(segment))) == nullptr) {
        const std::int64_t n = std::max<std::int64_t>(table->array_length(), 0);
        fail("'" + segment + "' is not an element of " + where + " (1.." + std::to_string(n) + ")");
      }
      key = LuaKey::at(std::stoll(segment));
    } else if (is_record(kind)) {
      const std::vector<std::string>& fields = fields_of(kind);
      if (std::find(fields.begin(), fields.end(), segment) == fields.end()) {
        if (kind != TableKind::kRoot || params.empty()) {
          fail("unknown field '" + segment + "'" + suggest(segment, fields, "known fields"));
        }
        std::vector<std::string> names = fields;
        names.insert(names.end(), params.begin(), params.end());
        const std::string close = suggest(segment, names, "");
        fail("unknown field or param '" + segment + "'" +
             (close.rfind(" (did you mean", 0) == 0
                  ? close
                  : " (known fields: " + join(fields) + "; params: " + join(params) + ")"));
      }
      key = LuaKey::named(segment);
    } else {
      fail("'" + where + "' has no fields");
    }
    chain.push_back(key);
    where += (where.empty() ? "" : ".") + segment;
    if (i + 1 == o.segments.size()) {
      table->set(key, o.value.to_lua_value());
      break;
    }
    LuaValue* child = table->find(key);
    if (child == nullptr) {   // a known field that is absent: becomes a table
      LuaValue empty;
      empty.type = LuaValue::Type::kTable;
      table->set(key, std::move(empty));
      child = table->find(key);
    }
    kind = child_kind(kind, key);
    table = child;
  }
  return chain;
}

}  // namespace graspsim::scripting::detail
