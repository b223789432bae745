// The fuzzers whose reader takes a file name (mesh readers, trace reader) write each input to one
// scratch file per process, in /dev/shm when it is there (a RAM file: no disk write per input).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace graspsim::fuzz {

// The scratch file's name, "<dir>/graspsim-fuzz-<pid><suffix>", removed at exit.
inline const std::string& scratch_path(const char* suffix) {
  static const std::string path = [suffix] {
    const char* dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    return std::string(dir) + "/graspsim-fuzz-" + std::to_string(getpid()) + suffix;
  }();
  static const bool registered = [] { return std::atexit([] { std::remove(path.c_str()); }) == 0; }();
  (void)registered;
  return path;
}

// Writes `size` bytes to the scratch file (replacing what it held) and returns its name.
inline const std::string& write_scratch(const std::uint8_t* data, std::size_t size, const char* suffix) {
  const std::string& path = scratch_path(suffix);
  std::FILE* out = std::fopen(path.c_str(), "wb");
  if (out == nullptr || (size > 0 && std::fwrite(data, 1, size, out) != size) || std::fclose(out) != 0) {
    std::perror(path.c_str());
    std::abort();   // the harness itself failed, not the code under test
  }
  return path;
}

}  // namespace graspsim::fuzz
