// The UDP device protocol: byte layouts (hw/README.md, "UDP protocol"). Every field is written
// byte by byte, little-endian, so the wire format does not depend on the host's byte order,
// alignment or struct padding.
#include "graspsim/hw/udp_protocol.hpp"

#include <cmath>
#include <cstring>

namespace graspsim::hw::udp {
namespace {

void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_f64(std::uint8_t* p, double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(bits >> (8 * i));
}
std::uint16_t get_u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
std::uint32_t get_u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}
double get_f64(const std::uint8_t* p) {
  std::uint64_t bits = 0;
  for (int i = 0; i < 8; ++i) bits |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

void put_header(std::uint8_t* out, MessageType type) {
  std::memcpy(out, kMagic.data(), kMagic.size());
  put_u16(out + 4, kVersion);
  put_u16(out + 6, static_cast<std::uint16_t>(type));
}

std::size_t size_of(MessageType type) {
  switch (type) {
    case MessageType::kHello: return kHelloSize;
    case MessageType::kSample: return kSampleSize;
    case MessageType::kForce: return kForceSize;
  }
  return 0;
}

// The header checks every decoder shares: magic, version, the expected type, the exact size.
DecodeStatus check(const std::uint8_t* data, std::size_t size, MessageType expected) {
  MessageType type;
  const DecodeStatus status = peek_type(data, size, &type);
  if (status != DecodeStatus::kOk) return status;
  if (type != expected) return DecodeStatus::kBadType;
  if (size != size_of(type)) return DecodeStatus::kBadSize;
  return DecodeStatus::kOk;
}

// Reads n doubles from p into out; false if any is NaN or infinite.
bool get_finite(const std::uint8_t* p, int n, double* out) {
  for (int i = 0; i < n; ++i) {
    out[i] = get_f64(p + 8 * i);
    if (!std::isfinite(out[i])) return false;
  }
  return true;
}

}  // namespace

static_assert(kVersion == 2, "describe(kBadVersion) names the version: update it with kVersion");

const char* describe(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::kOk: return "ok";
    case DecodeStatus::kTooShort: return "shorter than the 8-byte header";
    case DecodeStatus::kBadMagic: return "wrong magic (not a graspsim device datagram)";
    case DecodeStatus::kBadVersion: return "unsupported protocol version (this graspsim speaks version 2 only)";
    case DecodeStatus::kBadType: return "unknown or unexpected message type";
    case DecodeStatus::kBadSize: return "wrong size for its message type";
    case DecodeStatus::kNotFinite: return "a NaN or infinite number";
    case DecodeStatus::kBadMode: return "no valid server mode (bytes 72-75 must be 1 streaming or 2 lockstep, 76-79 zero)";
  }
  return "?";
}

const char* describe(Mode mode) {
  switch (mode) {
    case Mode::kStreaming: return "streaming";
    case Mode::kLockstep: return "lockstep";
  }
  return "?";
}

bool peek_version(const std::uint8_t* data, std::size_t size, std::uint16_t* version) {
  if (data == nullptr || size < kHeaderSize || std::memcmp(data, kMagic.data(), kMagic.size()) != 0) return false;
  *version = get_u16(data + 4);
  return true;
}

DecodeStatus peek_type(const std::uint8_t* data, std::size_t size, MessageType* type) {
  if (data == nullptr || size < kHeaderSize) return DecodeStatus::kTooShort;
  if (std::memcmp(data, kMagic.data(), kMagic.size()) != 0) return DecodeStatus::kBadMagic;
  if (get_u16(data + 4) != kVersion) return DecodeStatus::kBadVersion;
  const std::uint16_t t = get_u16(data + 6);
  if (t < static_cast<std::uint16_t>(MessageType::kHello) || t > static_cast<std::uint16_t>(MessageType::kForce)) {
    return DecodeStatus::kBadType;
  }
  *type = static_cast<MessageType>(t);
  return DecodeStatus::kOk;
}

std::size_t encode(const Hello& m, std::uint8_t* out) {
  put_header(out, MessageType::kHello);
  put_u32(out + 8, m.sequence);
  put_u32(out + 12, 0);   // reserved
  return kHelloSize;
}

std::size_t encode(const Sample& m, std::uint8_t* out) {
  put_header(out, MessageType::kSample);
  put_u32(out + 8, m.sequence);
  put_u32(out + 12, m.buttons);
  put_f64(out + 16, m.device_time);
  for (int i = 0; i < 3; ++i) put_f64(out + 24 + 8 * i, m.position[i]);
  for (int i = 0; i < 3; ++i) put_f64(out + 48 + 8 * i, m.gimbal[i]);
  put_u32(out + 72, static_cast<std::uint32_t>(m.mode));
  put_u32(out + 76, 0);   // reserved: zero
  return kSampleSize;
}

std::size_t encode(const Force& m, std::uint8_t* out) {
  put_header(out, MessageType::kForce);
  put_u32(out + 8, m.sequence);
  put_u32(out + 12, m.answers);
  for (int i = 0; i < 3; ++i) put_f64(out + 16 + 8 * i, m.force[i]);
  return kForceSize;
}

DecodeStatus decode(const std::uint8_t* data, std::size_t size, Hello* out) {
  const DecodeStatus status = check(data, size, MessageType::kHello);
  if (status != DecodeStatus::kOk) return status;
  out->sequence = get_u32(data + 8);   // bytes 12-15 are reserved: ignored
  return DecodeStatus::kOk;
}

DecodeStatus decode(const std::uint8_t* data, std::size_t size, Sample* out) {
  const DecodeStatus status = check(data, size, MessageType::kSample);
  if (status != DecodeStatus::kOk) return status;
  Sample m;
  m.sequence = get_u32(data + 8);
  m.buttons = get_u32(data + 12);
  if (!get_finite(data + 16, 1, &m.device_time) || !get_finite(data + 24, 3, m.position) ||
      !get_finite(data + 48, 3, m.gimbal)) {
    return DecodeStatus::kNotFinite;
  }
  // Strict: the mode must be one of the two, never a default, and the reserved word zero, so a
  // server that forgets to declare (or a v3 meaning in those bytes) is refused, not guessed.
  const std::uint32_t mode = get_u32(data + 72);
  if ((mode != static_cast<std::uint32_t>(Mode::kStreaming) && mode != static_cast<std::uint32_t>(Mode::kLockstep)) ||
      get_u32(data + 76) != 0) {
    return DecodeStatus::kBadMode;
  }
  m.mode = static_cast<Mode>(mode);
  *out = m;
  return DecodeStatus::kOk;
}

DecodeStatus decode(const std::uint8_t* data, std::size_t size, Force* out) {
  const DecodeStatus status = check(data, size, MessageType::kForce);
  if (status != DecodeStatus::kOk) return status;
  Force m;
  m.sequence = get_u32(data + 8);
  m.answers = get_u32(data + 12);
  if (!get_finite(data + 16, 3, m.force)) return DecodeStatus::kNotFinite;
  *out = m;
  return DecodeStatus::kOk;
}

}  // namespace graspsim::hw::udp
