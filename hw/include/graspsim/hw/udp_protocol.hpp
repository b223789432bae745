// The UDP device protocol, version 1 (hw/README.md, "UDP protocol"): fixed-size little-endian
// binary datagrams between graspsim and a device server (a lab PC with the vendor SDK, a ROS
// node, tools/device_server). Three messages, each starting with the same 8-byte header:
//   hello  (graspsim -> device): "send your samples to me"; the server learns our address.
//   sample (device -> graspsim): one reading of the device, SI units, the server's frame.
//   force  (graspsim -> device): the force to render (N), and which sample it answers.
// Decoding is strict: a datagram of the wrong size, magic, version or type, or with a
// non-finite number, is refused with its reason and never used.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace graspsim::hw::udp {

inline constexpr std::array<std::uint8_t, 4> kMagic = {'G', 'S', 'D', 'V'};   // bytes 0-3
inline constexpr std::uint16_t kVersion = 1;   // bumped on any change of layout or meaning

enum class MessageType : std::uint16_t { kHello = 1, kSample = 2, kForce = 3 };

inline constexpr std::size_t kHeaderSize = 8;    // bytes: magic, version, type
inline constexpr std::size_t kHelloSize = 16;    // bytes
inline constexpr std::size_t kSampleSize = 72;   // bytes
inline constexpr std::size_t kForceSize = 40;    // bytes
inline constexpr std::size_t kMaxDatagram = 72;  // bytes: the largest message

struct Hello {
  std::uint32_t sequence = 0;   // 1: graspsim's datagram counter (hellos and forces share it)
};

struct Sample {
  std::uint32_t sequence = 0;       // 1: the server's sample counter, +1 per sample produced
  std::uint32_t buttons = 0;        // bit i set while button i is pressed
  double device_time = 0.0;         // s: the device's own clock at the reading
  double position[3] = {0, 0, 0};   // m: the haptic interface point, in the server's frame
  double gimbal[3] = {0, 0, 0};     // rad: roll, pitch, yaw; 0 without a gimbal
};

struct Force {
  std::uint32_t sequence = 0;   // 1: graspsim's datagram counter (hellos and forces share it)
  std::uint32_t answers = 0;    // 1: sequence of the newest sample graspsim had when it computed this
  double force[3] = {0, 0, 0};  // N: force to render, in the server's frame (already clamped)
};

enum class DecodeStatus {
  kOk,
  kTooShort,    // fewer bytes than the header
  kBadMagic,    // bytes 0-3 are not kMagic
  kBadVersion,  // version is not kVersion
  kBadType,     // an unknown type, or not the type the receiver expects
  kBadSize,     // the size does not match the type's fixed size
  kNotFinite,   // a NaN or infinite double
};
const char* describe(DecodeStatus status);   // "wrong size for its type", ...

// Reads the header only: the message type of a datagram, or why it has none.
DecodeStatus peek_type(const std::uint8_t* data, std::size_t size, MessageType* type);

// encode_* write exactly k*Size bytes to `out` (which must hold them) and return that size.
std::size_t encode(const Hello& message, std::uint8_t* out);
std::size_t encode(const Sample& message, std::uint8_t* out);
std::size_t encode(const Force& message, std::uint8_t* out);

// decode_* accept exactly one message of their type; `out` is written only on kOk.
DecodeStatus decode(const std::uint8_t* data, std::size_t size, Hello* out);
DecodeStatus decode(const std::uint8_t* data, std::size_t size, Sample* out);
DecodeStatus decode(const std::uint8_t* data, std::size_t size, Force* out);

}  // namespace graspsim::hw::udp
