// Error messages of the scenario loader: the internal error type, "did you mean" suggestions,
// number formatting, and the context added to Lua's own messages.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace graspsim::scripting::detail {

// A problem with the scenario table or a --set; the loader prefixes the file path.
class ConversionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Optimal string alignment distance: insertions, deletions, substitutions and swaps of two
// neighbours each cost 1 ("mas" -> "mass" is 1, "stifnfess" -> "stiffness" is 1).
std::size_t edit_distance(const std::string& a, const std::string& b);

// " (did you mean 'mass'?)" when a known name is close to `unknown`, else
// " (<kind>: a, b, c)" listing them all, e.g. kind = "known fields".
std::string suggest(const std::string& unknown, const std::vector<std::string>& known,
                    const std::string& kind);

// "a, b, c"
std::string join(const std::vector<std::string>& names, const std::string& separator = ", ");

std::string format_exact(double value);   // %.17g: reads back to the same double
std::string format_short(double value);   // shortest text that reads back the same: for messages

// Lua's message "path:12: boom\nstack traceback: ..." with " (context)" added to its first line,
// and "path: " in front when it does not already start with the file path.
std::string with_context(const std::string& message, const std::string& path,
                         const std::string& context);

}  // namespace graspsim::scripting::detail
