// Processes and files for the end-to-end fault tests: a command started in the background (to
// signal, stop or race it), a command under a file-size limit, a small tmpfs, and a file's bytes.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace graspsim::test {

// The bytes of a file; nullopt when it cannot be read (missing).
inline std::optional<std::string> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline bool exists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::exists(std::filesystem::symlink_status(path, ec));
}

// How a child process ended: its exit status, or the signal that ended it.
struct Ended {
  int status = -1;   // exit status; -1 when a signal ended it
  int signal = 0;    // the signal that ended it; 0 when it exited
  std::string output;   // what it printed (stdout and stderr)
};

// `argv` started in the background in `directory` ("" for this one), its output to `log`;
// optionally under a file-size limit (RLIMIT_FSIZE, bytes). wait() reaps it.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::string& log, const std::string& directory = "",
        rlim_t file_size_limit = RLIM_INFINITY)
      : log_(log) {
    pid_ = fork();
    if (pid_ == 0) {
      if (!directory.empty() && chdir(directory.c_str()) != 0) _exit(126);
      const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd >= 0) {
        dup2(fd, 1);
        dup2(fd, 2);
        close(fd);
      }
      if (file_size_limit != RLIM_INFINITY) {
        struct rlimit limit{file_size_limit, file_size_limit};
        if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(126);
      }
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execv(args[0], args.data());
      _exit(127);
    }
  }
  ~Child() {
    if (pid_ > 0 && !reaped_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  pid_t pid() const { return pid_; }
  bool running() {
    if (reaped_) return false;
    int raw = 0;
    if (waitpid(pid_, &raw, WNOHANG) == pid_) {
      reaped_ = true;
      raw_ = raw;
      return false;
    }
    return true;
  }
  Ended wait() {
    if (!reaped_) {
      waitpid(pid_, &raw_, 0);
      reaped_ = true;
    }
    Ended e;
    if (WIFEXITED(raw_)) e.status = WEXITSTATUS(raw_);
    if (WIFSIGNALED(raw_)) e.signal = WTERMSIG(raw_);
    e.output = file_bytes(log_).value_or("");
    return e;
  }

 private:
  std::string log_;
  pid_t pid_ = -1;
  int raw_ = 0;
  bool reaped_ = false;
};

// A tmpfs of `bytes` mounted at `directory` (created) for the test's lifetime, where the machine
// allows it (mount(2) needs CAP_SYS_ADMIN); `why_not` says why not otherwise.
class Tmpfs {
 public:
  Tmpfs(const std::string& directory, std::size_t bytes) : directory_(directory) {
    std::error_code ec;
    std::filesystem::create_directories(directory, ec);
    const std::string options = "size=" + std::to_string(bytes);
    if (mount("tmpfs", directory.c_str(), "tmpfs", MS_NOSUID | MS_NODEV, options.c_str()) == 0) {
      mounted_ = true;
    } else {
      why_not_ = "cannot mount a tmpfs of " + std::to_string(bytes) + " bytes at " + directory + ": " +
                 std::strerror(errno);
    }
  }
  ~Tmpfs() {
    if (mounted_) umount2(directory_.c_str(), MNT_DETACH);
  }
  Tmpfs(const Tmpfs&) = delete;
  Tmpfs& operator=(const Tmpfs&) = delete;

  bool mounted() const { return mounted_; }
  const std::string& why_not() const { return why_not_; }
  const std::string& directory() const { return directory_; }

 private:
  std::string directory_;
  bool mounted_ = false;
  std::string why_not_;
};

}  // namespace graspsim::test
