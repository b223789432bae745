// Helpers for the scripting tests: where the test scenarios are, variants of them written to the
// build's temporary directory, and the message of the ScenarioError an action throws.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <catch2/catch.hpp>

#include "graspsim/scripting/scenario.hpp"

namespace scripting_test {

inline std::string data_path(const std::string& name) {
  return std::string(GRASPSIM_SOURCE_DIR) + "/tests/scripting/data/" + name;
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Writes `text` to <build>/test-tmp/scripting/<name> and returns the path.
inline std::string write_scenario(const std::string& name, const std::string& text) {
  const std::filesystem::path dir = std::filesystem::path(GRASPSIM_TEST_TMP) / "scripting";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// data/<base> with `from` replaced by `to` (which must occur exactly once), written as <name>.
inline std::string variant(const std::string& base, const std::string& name,
                           const std::string& from, const std::string& to) {
  std::string text = read_text(data_path(base));
  const std::size_t at = text.find(from);
  if (at == std::string::npos || text.find(from, at + 1) != std::string::npos) {
    throw std::logic_error("variant: '" + from + "' must occur exactly once in " + base);
  }
  text.replace(at, from.size(), to);
  return write_scenario(name, text);
}

// 1-based line of the first line of the file containing `marker`.
inline int line_of(const std::string& path, const std::string& marker) {
  std::istringstream text(read_text(path));
  std::string line;
  for (int n = 1; std::getline(text, line); ++n) {
    if (line.find(marker) != std::string::npos) return n;
  }
  throw std::logic_error("line_of: no '" + marker + "' in " + path);
}

// The message of the ScenarioError `action` throws; fails the test if it throws nothing or
// something else.
template <typename Action>
std::string error_of(Action&& action) {
  try {
    action();
  } catch (const graspsim::scripting::ScenarioError& e) {
    return e.what();
  }
  FAIL("expected a ScenarioError, but nothing was thrown");
  return {};
}

inline std::string load_error(const std::string& path,
                              const graspsim::scripting::LoadOptions& options = {}) {
  return error_of([&] { graspsim::scripting::Scenario::load(path, options); });
}

}  // namespace scripting_test
