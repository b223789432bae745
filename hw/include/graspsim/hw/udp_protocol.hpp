// The UDP device protocol, version 2 (hw/README.md, "UDP protocol"): fixed-size little-endian
// binary datagrams between graspsim and a device server (a lab PC with the vendor SDK, a ROS
// node, tools/device_server). Three messages, each starting with the same 8-byte header:
//   hello  (graspsim -> device): "send your samples to me"; the server learns our address.
//   sample (device -> graspsim): one reading of the device, SI units, the server's frame, and
//                                the server's mode (streaming or lockstep).
//   force  (graspsim -> device): the force to render (N), and which sample it answers.
// Decoding is strict: a datagram of the wrong size, magic, version or type, or with a
// non-finite number, is refused with its reason and never used.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace graspsim::hw::udp {

inline constexpr std::array<std::uint8_t, 4> kMagic = {'G', 'S', 'D', 'V'};   // bytes 0-3
// Bumped on any change of layout or meaning. 2: every sample declares the server's mode, so a
// client's `,lockstep` is not the user's word alone (v1 has no mode); v1 datagrams are refused.
inline constexpr std::uint16_t kVersion = 2;

enum class MessageType : std::uint16_t { kHello = 1, kSample = 2, kForce = 3 };

inline constexpr std::size_t kHeaderSize = 8;    // bytes: magic, version, type
inline constexpr std::size_t kHelloSize = 16;    // bytes
inline constexpr std::size_t kSampleSize = 80;   // bytes (72 in v1: + mode and reserved)
inline constexpr std::size_t kForceSize = 40;    // bytes
inline constexpr std::size_t kMaxDatagram = 80;  // bytes: the largest message

// What a server is, declared in every sample (bytes 72-75). 0 is no mode: a server must say.
//   kStreaming: samples come at the device's own rate whatever graspsim does (a real device,
//               or a simulation on its own clock); the client must pace and protect the run.
//   kLockstep:  exactly one sample answers each hello or force, and nothing else comes (a
//               simulated or replaying peer that waits for graspsim: no hand on a device).
enum class Mode : std::uint32_t { kStreaming = 1, kLockstep = 2 };
const char* describe(Mode mode);   // "streaming", "lockstep"

struct Hello {
  std::uint32_t sequence = 0;   // 1: graspsim's datagram counter (hellos and forces share it)
};

struct Sample {
  std::uint32_t sequence = 0;       // 1: the server's sample counter, +1 per sample produced
  std::uint32_t buttons = 0;        // bit i set while button i is pressed
  double device_time = 0.0;         // s: the device's own clock at the reading
  double position[3] = {0, 0, 0};   // m: the haptic interface point, in the server's frame
  double gimbal[3] = {0, 0, 0};     // rad: roll, pitch, yaw; 0 without a gimbal
  Mode mode = Mode::kStreaming;     // the server's mode (streaming: the safe assumption)
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
  kBadMode,     // a sample's mode is not 1 (streaming) or 2 (lockstep), or its reserved bytes are not 0
};
const char* describe(DecodeStatus status);   // "wrong size for its type", ...

// Reads the header only: the message type of a datagram, or why it has none.
DecodeStatus peek_type(const std::uint8_t* data, std::size_t size, MessageType* type);
// The version field (bytes 4-5) of a datagram with the magic, for error messages; false for
// anything shorter than the header or without the magic.
bool peek_version(const std::uint8_t* data, std::size_t size, std::uint16_t* version);

// encode_* write exactly k*Size bytes to `out` (which must hold them) and return that size.
std::size_t encode(const Hello& message, std::uint8_t* out);
std::size_t encode(const Sample& message, std::uint8_t* out);
std::size_t encode(const Force& message, std::uint8_t* out);

// decode_* accept exactly one message of their type; `out` is written only on kOk.
DecodeStatus decode(const std::uint8_t* data, std::size_t size, Hello* out);
DecodeStatus decode(const std::uint8_t* data, std::size_t size, Sample* out);
DecodeStatus decode(const std::uint8_t* data, std::size_t size, Force* out);

}  // namespace graspsim::hw::udp
