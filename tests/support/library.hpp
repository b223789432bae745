// Paths tests share: the library's scenarios, and a fresh file in the tests' temporary folder.
#pragma once

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace graspsim::test {

// Every scenarios/*.lua of the source tree, full paths, sorted (directory order is the file
// system's, not ours).
inline std::vector<std::string> library_scenarios() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(GRASPSIM_SOURCE_DIR) + "/scenarios"))
    if (entry.path().extension() == ".lua") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

// GRASPSIM_TEST_TMP/<prefix><name>, removed if a file is there from an earlier run.
inline std::string fresh_tmp_path(const std::string& prefix, const std::string& name) {
  const std::string path = std::string(GRASPSIM_TEST_TMP) + "/" + prefix + name;
  std::remove(path.c_str());
  return path;
}

}  // namespace graspsim::test
