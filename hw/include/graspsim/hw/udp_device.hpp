// UdpDevice: a finger driven by a device server over UDP (hw/README.md, "UDP protocol"). The
// link logic (sequence numbers, hold, timeout, counters) is UdpLink, which sees only bytes and
// graspsim's time, so it is tested without sockets; UdpDevice adds a non-blocking POSIX socket.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "graspsim/hw/device.hpp"
#include "graspsim/hw/force_safety.hpp"
#include "graspsim/hw/udp_protocol.hpp"

namespace graspsim::hw {

// The device model whose limits a UDP device gets when its spec names none: the weakest in the
// table (Touch / Omni: 3.3 N peak, 0.88 N continuous). A UDP server cannot say what it drives;
// a limit too low only feels weak, one too high can overheat a small device's motors.
inline constexpr const char* kUdpDefaultModel = "touch";

// Force safety for a device of model `key` (device_models.hpp): its peak and continuous force,
// ForceSafetyConfig's defaults for the rest. Throws std::invalid_argument for an unknown key.
ForceSafetyConfig udp_safety_of_model(const std::string& key);

struct UdpDeviceConfig {
  std::string host = "127.0.0.1";   // the device server: a numeric address or a host name
  std::uint16_t port = 0;            // the device server's UDP port
  std::uint16_t local_port = 0;      // our UDP port; 0 = any free port
  double timeout_s = 0.05;           // s, graspsim time: no new sample for longer -> link lost, force 0
  DeviceLimits limits{};             // the clamp every rendered force goes through (the finger's)
  // Lockstep (tests, `device_server --lockstep`): the server answers every datagram we send with
  // exactly one datagram, and read() first waits for the answers to all we sent, so the run
  // does not depend on timing. Off for a real device: read() never waits. Either way every
  // sample must declare the same mode (protocol v2): a mismatch is an error, never a guess.
  bool lockstep = false;
  double answer_wait_s = 10.0;   // s, wall clock, lockstep only: an unanswered datagram is an error
  double handshake_s = 2.0;      // s, wall clock: make_udp_device waits this long for the first
                                 //   sample (in lockstep: answer_wait_s for the hello's answer;
                                 //   0 = do not wait, in either mode)
  // The device's own limits, applied to every force sent after the clamp above (peak, thermal
  // continuous limit, ramp-in after start, link loss and release), on graspsim's time (the
  // `time` of the last read). limits() is the smaller of the two peaks.
  ForceSafetyConfig safety = udp_safety_of_model(kUdpDefaultModel);
  std::string model = kUdpDefaultModel;   // where `safety` came from, for describe()
};

// Counts since the device was made (the trace has the per-tick `sequence` and `new_samples`
// instead: Device::sample_sequence).
struct UdpCounters {
  std::uint64_t received = 0;    // samples accepted (newer than every sample before)
  std::uint64_t lost = 0;        // sample sequence numbers skipped between accepted samples
  std::uint64_t late = 0;        // valid samples not newer than the newest (late or duplicate): dropped
  std::uint64_t malformed = 0;   // datagrams refused by the decoder (any reason): dropped
  std::uint64_t held = 0;        // reads with no new sample: the last sample was returned again
  std::uint64_t link_lost = 0;   // times the link went from alive to lost (timeout)
};

// The receiving side of the link, without a socket: feed it datagrams, then ask for the sample
// of a read at graspsim time `time`. No heap allocation.
class UdpLink {
 public:
  // `expected`: the mode every sample must declare (lockstep for a `,lockstep` spec).
  explicit UdpLink(double timeout_s, udp::Mode expected = udp::Mode::kStreaming);
  // One received datagram (any bytes): a valid newer sample of the expected mode replaces the
  // newest; a valid sample of the other mode is never used and marks the link mismatched (for
  // good: the owner must stop); anything else is counted (late or malformed) and dropped.
  void accept(const std::uint8_t* data, std::size_t size);
  void count_malformed() { ++counters_.malformed; }   // a datagram too large to even read
  // The sample for a read at `time` (s): the newest sample; counts a hold when no new sample
  // came since the previous read, and declares the link lost when the last new sample was seen
  // at a read more than timeout_s before `time` (or none ever came). A new sample revives it.
  DeviceSample read(double time);
  bool link_lost() const { return lost_; }
  bool has_sample() const { return has_sample_; }
  const udp::Sample& newest() const { return newest_; }   // valid once has_sample()
  const UdpCounters& counters() const { return counters_; }
  double timeout_s() const { return timeout_s_; }
  udp::Mode expected_mode() const { return expected_; }
  // True once a valid sample declared the other mode; mismatch_sequence() is the first one's.
  bool mode_mismatch() const { return mismatch_; }
  std::uint32_t mismatch_sequence() const { return mismatch_sequence_; }
  // The last datagram refused by the decoder: why (kOk if none was), and its version field when
  // it had graspsim's magic (0 otherwise), so a start-up error can say "version 1 server".
  udp::DecodeStatus last_refusal() const { return last_refusal_; }
  std::uint16_t last_refused_version() const { return last_refused_version_; }

 private:
  double timeout_s_;             // s, graspsim time
  udp::Mode expected_;           // the mode every sample must declare
  bool mismatch_ = false;        // a valid sample declared the other mode
  std::uint32_t mismatch_sequence_ = 0;   // 1: the first such sample's sequence number
  udp::DecodeStatus last_refusal_ = udp::DecodeStatus::kOk;
  std::uint16_t last_refused_version_ = 0;   // 1: version field of the last refused datagram
  udp::Sample newest_{};         // the newest valid sample
  bool has_sample_ = false;
  bool fresh_ = false;           // a new sample came since the previous read
  bool lost_ = true;             // link lost: no sample yet, or timed out
  double last_fresh_time_ = 0;   // s, graspsim time of the read that last brought a new sample
  UdpCounters counters_{};
};

class UdpDevice final : public Device {
 public:
  // Opens a non-blocking UDP socket bound to config.local_port, connected to host:port (so only
  // the server's datagrams are received), and sends a hello. Throws std::runtime_error naming
  // the host, port or local port when it cannot.
  explicit UdpDevice(const UdpDeviceConfig& config);
  ~UdpDevice() override;
  UdpDevice(const UdpDevice&) = delete;
  UdpDevice& operator=(const UdpDevice&) = delete;

  // Drains the socket (non-blocking; in lockstep after waiting for the answers owed) and returns
  // the newest sample, in the server's frame and SI units. `tick` is not used. Throws
  // std::runtime_error (mode_mismatch_error()) once a sample declared the other mode.
  DeviceSample read(std::int64_t tick, double time) override;
  DeviceLimits limits() const override;    // N: min(config.limits, the safety's peak)
  std::string describe() const override;   // "udp 127.0.0.1:7001 (touch: 3.3 N peak, 0.88 N continuous)"
  // s: the newest sample's device time, from its datagram (0 before the first sample).
  bool has_sample_clock() const override { return true; }
  double sample_time() const override { return link_.has_sample() ? link_.newest().device_time : 0.0; }
  // 1: the newest sample's sequence number (-1 before the first); samples accepted by the last read.
  std::int64_t sample_sequence() const override {
    return link_.has_sample() ? static_cast<std::int64_t>(link_.newest().sequence) : -1;
  }
  std::int64_t new_samples() const override { return new_samples_; }

  // Waits (wall clock, at most max_wait_s) for the first sample, resending the hello every
  // 0.25 s; true once one came. Start-up only: never called from read().
  bool wait_for_first_sample(double max_wait_s);
  // Lockstep start-up: waits (wall clock, at most max_wait_s, no resend: one answer is owed per
  // datagram) for the answer to the hello; true once it came (a sample or not).
  bool wait_for_hello_answer(double max_wait_s);
  // "udp device HOST:PORT: the server at HOST:PORT streams samples (a real device?): ..." for
  // a mismatched link (the text tells the user what to change in the spec).
  std::string mode_mismatch_error() const;
  // Why no sample was accepted, for a start-up error: "" or "; N datagrams refused, the last:
  // protocol version 1 (this graspsim speaks version 2; update the server ...)".
  std::string refusal_note() const;
  bool mode_mismatch() const { return link_.mode_mismatch(); }
  // The start-up handshake make_udp_device runs: the first sample (wait_for_first_sample for
  // handshake_s; in lockstep wait_for_hello_answer for answer_wait_s), then its declared mode.
  // Throws std::runtime_error: no sample (with refusal_note()), or mode_mismatch_error().
  void start_up();

  const UdpCounters& counters() const { return link_.counters(); }
  bool link_lost() const { return link_.link_lost(); }
  const udp::Sample& newest() const { return link_.newest(); }   // with its sequence and device time
  bool has_sample() const { return link_.has_sample(); }
  const Vec3& last_force() const { return last_force_; }   // N: the force last sent (0 while lost)
  const ForceSafety& safety() const { return safety_; }
  std::uint32_t datagrams_sent() const { return sent_; }   // hellos and forces
  std::uint16_t local_port() const { return local_port_; } // the port actually bound
  const UdpDeviceConfig& config() const { return config_; }

 protected:
  // Sends a force datagram answering the newest sample, through ForceSafety at the last read's
  // time: zero while the link is lost (and the ramp re-armed, so force rises again after it).
  void output(const Vec3& force) override;
  // After release()'s zero: the next force ramps in again.
  void on_release() override { safety_.release(); }

 private:
  void send_hello();
  void send(const std::uint8_t* data, std::size_t size);
  void drain();
  bool wait_readable(double max_wait_s);

  UdpDeviceConfig config_;
  UdpLink link_;
  ForceSafety safety_;
  double time_ = 0.0;                  // s, graspsim time of the last read: ForceSafety's clock
  std::int64_t new_samples_ = 0;       // 1: samples the last read accepted
  std::uint64_t received_at_read_ = 0; // 1: counters().received after the last read
  int fd_ = -1;
  std::uint16_t local_port_ = 0;
  std::uint32_t sent_ = 0;             // datagrams sent: the next one's sequence number
  std::uint64_t answers_ = 0;          // datagrams received (any), for lockstep's accounting
  Vec3 last_force_{0.0, 0.0, 0.0};     // N
};

// The backend's factory: a UdpDevice, and (unless handshake_s = 0) its first sample waited for
// (in lockstep: the hello's one answer) and its declared mode checked; throws
// std::runtime_error "udp device HOST:PORT: no sample within S s ..." if none came, or the
// mode mismatch error, so either is the run's start-up error (exit 2, no force ever sent).
std::unique_ptr<Device> make_udp_device(const UdpDeviceConfig& config);

// Parses "HOST:PORT[,timeout=S][,local_port=N][,lockstep][,model=KEY][,max_force=N]
// [,continuous_force=N]" (a leading "udp:" is allowed) into a config: the safety limits of model
// KEY (default kUdpDefaultModel), then max_force / continuous_force (N) over them. Throws
// std::invalid_argument naming the spec and what is wrong.
UdpDeviceConfig parse_udp_spec(const std::string& spec);

}  // namespace graspsim::hw
