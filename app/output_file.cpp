// A run's output path: default name, inputs refused, and the claim (see output_file.hpp).
#include "app/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace graspsim::app {
namespace {

bool kept_byte(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
         c == '.';
}

bool same_file(const struct stat& a, const struct stat& b) { return a.st_dev == b.st_dev && a.st_ino == b.st_ino; }

// Both names lead to one existing file (symbolic links followed), or are one name.
bool same_path(const std::string& a, const std::string& b) {
  struct stat sa{}, sb{};
  if (stat(a.c_str(), &sa) == 0 && stat(b.c_str(), &sb) == 0) return same_file(sa, sb);
  std::error_code ec;
  return std::filesystem::weakly_canonical(a, ec) == std::filesystem::weakly_canonical(b, ec) && !ec;
}

std::string in_quotes(const std::string& text) { return "'" + text + "'"; }

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

}  // namespace

std::string not_replaceable(const std::string& path) {
  struct stat target{};
  if (stat(path.c_str(), &target) != 0 || S_ISREG(target.st_mode)) return "";   // nothing there, or a file
  struct stat link{};
  const bool linked = lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode);
  return std::string(linked ? "a symbolic link to " : "") + kind_of(target.st_mode);
}

void refuse_unreplaceable(const std::string& path, const OutputNaming& naming) {
  const std::string what = not_replaceable(path);
  if (what.empty()) return;
  const bool directory = what.ends_with("a directory");
  throw OutputError(naming.option + " " + in_quotes(path) + " is " + what +
                    ", not a regular file: graspsim replaces only regular files (it writes beside the path and "
                    "renames over it, which would put a file in place of " + (directory ? "the directory" : "it") +
                    "); " + (directory ? "name a file in it, or " : "") + naming.write_none);
}

std::string default_trace_name(const std::string& scenario_name) {
  const std::string name = scenario_name.substr(0, kMaxStem);
  std::string stem;
  for (std::size_t i = 0; i < name.size(); ++i) {
    // A dot first, last (before ".h5") or after a dot could make a hidden name or a "..".
    const bool bad_dot = name[i] == '.' && (i == 0 || i + 1 == name.size() || name[i - 1] == '.');
    stem += kept_byte(name[i]) && !bad_dot ? name[i] : '_';
  }
  return (stem.empty() ? "trace" : stem) + ".h5";
}

std::string partial_name(const std::string& out) { return out + ".partial"; }

void refuse_input_as_output(const std::string& out, const std::vector<InputFile>& inputs, const std::string& flag) {
  const std::string partial = partial_name(out);
  for (const InputFile& input : inputs) {
    if (same_path(out, input.path)) {
      throw OutputError(flag + " " + in_quotes(out) + " is " + input.what + " (" + in_quotes(input.path) +
                        "), a file this run reads or writes: it would be written over; choose another output");
    }
    if (same_path(partial, input.path)) {
      throw OutputError(flag + " " + in_quotes(out) + " is written as " + in_quotes(partial) + " until the run ends, and that is " +
                        input.what + " (" + in_quotes(input.path) + "), a file this run reads or writes; choose another output");
    }
  }
}

bool locked_by_a_run(const std::string& path) {
  // Non-blocking, and regular files only: opening a FIFO to read waits for a writer for ever
  // (the trace readers then refuse what is not a regular file, naming what it is).
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return false;
  struct stat st{};
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return false;
  }
  struct flock lock{};
  lock.l_type = F_WRLCK;
  lock.l_whence = SEEK_SET;
  const bool locked = fcntl(fd, F_OFD_GETLK, &lock) == 0 && lock.l_type != F_UNLCK;
  ::close(fd);
  return locked;
}

OutputClaim::OutputClaim(const std::string& out, const OutputNaming& naming)
    : out_(out), partial_(partial_name(out)), naming_(naming) {
  refuse_unreplaceable(out, naming);
  // The partial is created, or an empty one of a run that ended reused: never anything else.
  struct stat there{};
  if (lstat(partial_.c_str(), &there) == 0 && !S_ISREG(there.st_mode)) {
    throw OutputError(naming.option + " " + in_quotes(out) + " is written as " + in_quotes(partial_) +
                      " until the run ends, and that name is taken by " +
                      (S_ISLNK(there.st_mode) ? "a symbolic link" : kind_of(there.st_mode)) + ": move it away");
  }
  // A few rounds at most: a round is lost only when a run that held the partial renamed it away
  // between our open and our lock.
  for (int round = 0; round < 8; ++round) {
    int fd = open(partial_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    const bool created = fd >= 0;
    if (!created) {
      if (errno != EEXIST) throw OutputError("cannot create the trace " + in_quotes(partial_) + ": " + std::strerror(errno));
      // No O_CREAT, no O_TRUNC: changes nothing. Not through a link, and never a FIFO's wait.
      fd = open(partial_.c_str(), O_RDWR | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
      if (fd < 0) {
        if (errno == ENOENT) continue;
        throw OutputError("cannot open " + in_quotes(partial_) + ": " + std::strerror(errno));
      }
      struct stat opened{};
      if (fstat(fd, &opened) != 0 || !S_ISREG(opened.st_mode)) {
        ::close(fd);
        throw OutputError(in_quotes(partial_) + " is not a regular file: move it away to write " + in_quotes(out));
      }
    }
    struct flock lock{};
    lock.l_type = F_WRLCK;
    lock.l_whence = SEEK_SET;   // the whole file: start 0, length 0
    if (fcntl(fd, F_OFD_SETLK, &lock) != 0) {
      const int error = errno;
      ::close(fd);
      if (error == EAGAIN || error == EACCES) {
        throw OutputError("--out " + in_quotes(out) + ": another graspsim run is writing it (its partial trace " +
                          in_quotes(partial_) + " is locked); wait for that run to end, or choose another output");
      }
      throw OutputError("cannot lock " + in_quotes(partial_) + ": " + std::strerror(error));
    }
    fd_ = fd;
    if (!still_ours()) {   // renamed or removed by the run that held it: start again
      ::close(fd_);
      fd_ = -1;
      continue;
    }
    struct stat mine{};
    if (!created && fstat(fd_, &mine) == 0 && mine.st_size > 0) {
      ::close(fd_);
      fd_ = -1;
      throw OutputError(in_quotes(partial_) + " is the trace of a run that did not finish (killed?), kept as it was: "
                        "`graspsim repair " + partial_ + "` makes it readable by every HDF5 tool; move it away or "
                        "delete it to write " + in_quotes(out) + " again");
    }
    return;
  }
  throw OutputError("cannot claim " + in_quotes(partial_) + ": other runs keep taking it");
}

OutputClaim::~OutputClaim() {
  if (fd_ < 0) return;
  struct stat st{};
  if (!done_ && fstat(fd_, &st) == 0 && st.st_size == 0 && still_ours()) unlink(partial_.c_str());
  ::close(fd_);
}

bool OutputClaim::still_ours() const {
  struct stat named{}, held{};
  return fd_ >= 0 && stat(partial_.c_str(), &named) == 0 && fstat(fd_, &held) == 0 && same_file(named, held);
}

void OutputClaim::commit() {
  if (done_) return;
  if (const std::string what = not_replaceable(out_); !what.empty()) {
    throw OutputError(in_quotes(out_) + " became " + what + " while the run wrote its trace, and is not replaced: "
                      "the trace is kept under its partial name");
  }
  if (std::rename(partial_.c_str(), out_.c_str()) != 0) {
    throw OutputError("cannot rename the finished trace " + in_quotes(partial_) + " to " + in_quotes(out_) + ": " +
                      std::strerror(errno) + " (the trace is kept under its partial name)");
  }
  done_ = true;
}

void OutputClaim::abandon() {
  if (done_) return;
  if (still_ours()) unlink(partial_.c_str());
  done_ = true;
}

}  // namespace graspsim::app
