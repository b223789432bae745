// DiskReserve: an unlinked, preallocated file beside the trace (see disk_reserve.hpp).
#include "disk_reserve.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>
#include <string>
#include <vector>

namespace graspsim::recordings {
namespace {

// An open file in `directory` that has no name: O_TMPFILE where the file system has it, else a
// fresh name that is unlinked at once.
int unnamed_file(const std::string& directory) {
  int fd = open(directory.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd >= 0) return fd;
  std::string name = directory + "/.graspsim-reserve-XXXXXX";
  std::vector<char> buffer(name.begin(), name.end());
  buffer.push_back('\0');
  fd = mkostemp(buffer.data(), O_CLOEXEC);
  if (fd >= 0) unlink(buffer.data());
  return fd;
}

}  // namespace

DiskReserve::DiskReserve(const std::string& directory, std::size_t bytes) {
  if (bytes == 0) return;
  fd_ = unnamed_file(directory.empty() ? "." : directory);
  if (fd_ < 0) return;
  // posix_fallocate allocates the blocks (a sparse write would not); it returns its error.
  for (std::size_t n = bytes; n >= kSmallest; n /= 2) {
    if (posix_fallocate(fd_, 0, static_cast<off_t>(n)) == 0) {
      bytes_ = n;
      return;
    }
    if (ftruncate(fd_, 0) != 0) break;   // whatever a failed attempt allocated goes back
  }
  release();
}

void DiskReserve::release() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  bytes_ = 0;
}

}  // namespace graspsim::recordings
