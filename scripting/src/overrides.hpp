// --set overrides: parsing "path=value", and resolving a dotted path in the scenario table by the
// format (objects, fingers and expectations are addressed by name).
#pragma once

#include <string>
#include <vector>

#include "lua_value.hpp"

namespace graspsim::scripting::detail {

struct Override {
  std::string text;                    // "objects.box.mass=0.5", as given
  std::string path;                    // "objects.box.mass"
  std::vector<std::string> segments;   // {"objects", "box", "mass"}
  SetValue value;
  bool used = false;                   // taken by param() while the scenario ran
};

// Throws ConversionError("--set abc: ...") for a malformed override.
std::vector<Override> parse_overrides(const std::vector<std::string>& sets);

// Finds the override's path in `root` (a copy of the scenario table), creating missing fields
// that the format knows, sets the value there, and returns the keys that lead to it, to set the
// same value in the Lua table. Throws ConversionError("--set path=value: ...") when the path
// does not exist and is not a field of the format; a misspelt name may be one of the file's
// `params` (the names it called param() with), so those are suggested too.
std::vector<LuaKey> apply_override(LuaValue& root, const Override& override_,
                                   const std::vector<std::string>& params);

}  // namespace graspsim::scripting::detail
