// Runs a shell command for the end-to-end tests and captures what it printed.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace graspsim::test {

struct Outcome {
  int status;           // exit status (-1 when killed by a signal)
  std::string output;   // stdout and stderr together
};

// Runs `command` with /bin/sh, stderr joined to stdout (or dropped).
inline Outcome shell(const std::string& command, bool join_stderr = true) {
  FILE* pipe = popen((command + (join_stderr ? " 2>&1" : " 2>/dev/null")).c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot run: " + command);
  std::string out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
  const int raw = pclose(pipe);
  return Outcome{WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, out};
}

}  // namespace graspsim::test
