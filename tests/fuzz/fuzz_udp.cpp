// libFuzzer harness: the UDP datagram decoder (hw/src/udp_protocol.cpp), one datagram in.
// Properties (hw/README.md "UDP protocol": decoding is strict, fixed-size little-endian):
//  - every decoder reads only `size` bytes and returns a status with a description;
//  - a datagram decoded as a message re-encodes to the same bytes (a sample or force exactly;
//    a hello except its reserved bytes 12-15, which the decoder ignores), so nothing accepted is
//    guessed or normalised;
//  - a decoded datagram's type is the one peek_type reads, and a decoded sample holds only finite
//    numbers and a declared mode.
// A violation aborts (a finding), as does any sanitizer report.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "graspsim/hw/udp_protocol.hpp"

using namespace graspsim::hw::udp;

namespace {

void require(bool holds) {
  if (!holds) std::abort();
}

// Decodes as M; on success checks the type and the re-encoding, bytes [skip_from, skip_to) apart.
template <typename M>
void round_trip(const std::uint8_t* data, std::size_t size, MessageType type, std::size_t skip_from = 0,
                std::size_t skip_to = 0) {
  M message;
  const DecodeStatus status = decode(data, size, &message);
  require(describe(status) != nullptr);
  if (status != DecodeStatus::kOk) return;
  MessageType peeked{};
  require(peek_type(data, size, &peeked) == DecodeStatus::kOk && peeked == type);
  std::uint8_t out[kMaxDatagram];
  const std::size_t n = encode(message, out);
  require(n == size);
  for (std::size_t i = 0; i < n; ++i) require((i >= skip_from && i < skip_to) || out[i] == data[i]);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // An exact-size heap copy, so AddressSanitizer sees any read past the datagram's end.
  const std::vector<std::uint8_t> copy(data, data + size);
  const std::uint8_t* bytes = copy.empty() ? nullptr : copy.data();
  MessageType type{};
  require(describe(peek_type(bytes, size, &type)) != nullptr);
  std::uint16_t version = 0;
  (void)peek_version(bytes, size, &version);
  round_trip<Hello>(bytes, size, MessageType::kHello, 12, 16);
  round_trip<Force>(bytes, size, MessageType::kForce);
  round_trip<Sample>(bytes, size, MessageType::kSample);
  Sample sample;
  if (decode(bytes, size, &sample) == DecodeStatus::kOk) {
    require(std::isfinite(sample.device_time));
    for (int i = 0; i < 3; ++i) require(std::isfinite(sample.position[i]) && std::isfinite(sample.gimbal[i]));
    require(sample.mode == Mode::kStreaming || sample.mode == Mode::kLockstep);
  }
  return 0;
}
