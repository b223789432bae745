// Message helpers of the scenario loader.
#include "messages.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace graspsim::scripting::detail {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  // d[i][j]: distance between the first i characters of a and the first j of b.
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

std::string join(const std::vector<std::string>& names, const std::string& separator) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += separator;
    out += names[i];
  }
  return out;
}

std::string suggest(const std::string& unknown, const std::vector<std::string>& known,
                    const std::string& kind) {
  // Close enough to be a typo: about one edit in three characters, at least one. Case is
  // ignored ("Mass" -> "mass"). Ties go to the earlier name in `known` (a fixed order).
  const auto lower = [](std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  };
  const std::size_t allowed = std::max<std::size_t>(1, (unknown.size() + 1) / 3);
  const std::string* best = nullptr;
  std::size_t best_distance = allowed + 1;
  for (const std::string& name : known) {
    const std::size_t distance = edit_distance(lower(unknown), lower(name));
    if (distance < best_distance) {
      best = &name;
      best_distance = distance;
    }
  }
  if (best != nullptr) return " (did you mean '" + *best + "'?)";
  if (known.empty()) return " (there are no " + kind + ")";
  return " (" + kind + ": " + join(known) + ")";
}

std::string format_exact(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

std::string format_short(double value) {
  if (std::isnan(value)) return "nan";   // whatever its sign bit
  char buffer[40];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::string with_context(const std::string& message, const std::string& path,
                         const std::string& context) {
  std::string out = message;
  if (!context.empty()) {
    const std::size_t end = std::min(out.find('\n'), out.size());
    out.insert(end, " (" + context + ")");
  }
  if (out.rfind(path + ":", 0) != 0) out = path + ": " + out;
  return out;
}

}  // namespace graspsim::scripting::detail
