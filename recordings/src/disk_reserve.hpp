// DiskReserve: room held on a trace's file system so that a run cut by a full disk can still
// close its trace and write its status (recordings/README.md "A full disk").
#pragma once

#include <cstddef>
#include <string>
#include <utility>

namespace graspsim::recordings {

class DiskReserve {
 public:
  DiskReserve() = default;
  // Allocates `bytes` (halving down to kSmallest when the file system has less room; none below
  // that) in an unlinked file in `directory`: no name is ever seen, and the kernel frees the
  // room when the process ends, however it ends.
  DiskReserve(const std::string& directory, std::size_t bytes);
  ~DiskReserve() { release(); }
  DiskReserve(DiskReserve&& other) noexcept
      : fd_(std::exchange(other.fd_, -1)), bytes_(std::exchange(other.bytes_, 0)) {}
  DiskReserve& operator=(DiskReserve&& other) noexcept {
    if (this != &other) {
      release();
      fd_ = std::exchange(other.fd_, -1);
      bytes_ = std::exchange(other.bytes_, 0);
    }
    return *this;
  }

  // Gives the room back to the file system (idempotent).
  void release();
  std::size_t bytes() const { return bytes_; }   // bytes held now

  static constexpr std::size_t kSmallest = 16 * 1024;   // bytes

 private:
  int fd_ = -1;
  std::size_t bytes_ = 0;   // bytes
};

}  // namespace graspsim::recordings
