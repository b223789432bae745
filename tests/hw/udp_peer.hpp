// An in-process fake device server for the UdpDevice tests: a UDP socket on 127.0.0.1 that
// learns the device's address from its hello and answers as the test tells it. Like a real
// server it declares one mode (protocol v2), stamped on every sample send(Sample) sends:
// lockstep unless told (most tests drive it in lockstep); send(bytes) sends anything. No heap
// allocation in send/receive (the no-allocation test runs it between its counted calls).
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "graspsim/hw/udp_protocol.hpp"

namespace graspsim::test {

namespace udp = graspsim::hw::udp;

class UdpPeer {
 public:
  explicit UdpPeer(udp::Mode mode = udp::Mode::kLockstep) : mode_(mode) {
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
      throw std::runtime_error("test peer: cannot bind a loopback UDP socket");
    }
    socklen_t len = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
  }
  ~UdpPeer() { ::close(fd_); }
  UdpPeer(const UdpPeer&) = delete;
  UdpPeer& operator=(const UdpPeer&) = delete;

  std::uint16_t port() const { return port_; }

  // Receives one datagram into buffer() and returns its size. The 10 s poll is a guard against
  // a hung test, not a measured threshold: on loopback the datagram is already queued.
  std::size_t receive() {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 10000) != 1) throw std::runtime_error("test peer: nothing received in 10 s");
    socklen_t len = sizeof device_;
    const ssize_t n = ::recvfrom(fd_, buf_, sizeof buf_, 0, reinterpret_cast<sockaddr*>(&device_), &len);
    if (n < 0) throw std::runtime_error("test peer: recvfrom failed");
    return static_cast<std::size_t>(n);
  }
  const std::uint8_t* buffer() const { return buf_; }

  udp::Force receive_force() {
    const std::size_t n = receive();
    udp::Force f;
    if (udp::decode(buf_, n, &f) != udp::DecodeStatus::kOk) throw std::runtime_error("test peer: not a force");
    return f;
  }
  udp::Hello receive_hello() {
    const std::size_t n = receive();
    udp::Hello h;
    if (udp::decode(buf_, n, &h) != udp::DecodeStatus::kOk) throw std::runtime_error("test peer: not a hello");
    return h;
  }

  // Sends bytes to the device (whose address the last receive() learnt).
  void send(const void* data, std::size_t size) {
    ::sendto(fd_, data, size, 0, reinterpret_cast<const sockaddr*>(&device_), sizeof device_);
  }
  void send(udp::Sample s) {
    s.mode = mode_;
    std::uint8_t b[udp::kSampleSize];
    send(b, udp::encode(s, b));
  }
  udp::Mode mode() const { return mode_; }

 private:
  udp::Mode mode_;   // declared in every sample send(Sample) sends
  int fd_ = -1;
  std::uint16_t port_ = 0;
  sockaddr_in device_{};
  std::uint8_t buf_[512];
};

// Sample n of a simple scripted motion: seq n, device time n ms, a line in x and y.
inline udp::Sample line_sample(std::uint32_t n) {
  udp::Sample s;
  s.sequence = n;
  s.device_time = n * 1e-3;
  s.position[0] = 1e-3 * n;
  s.position[1] = -2e-3 * n;
  s.position[2] = 0.5;
  s.gimbal[0] = 0.1;
  s.gimbal[1] = 0.2;
  s.gimbal[2] = 0.3 + 1e-4 * n;
  s.buttons = n & 3u;
  return s;
}

}  // namespace graspsim::test
