// UdpDevice and UdpLink (hw/README.md, "UDP protocol").
#include "graspsim/hw/udp_device.hpp"

#include "graspsim/hw/device_models.hpp"

#include <algorithm>
#include <arpa/inet.h>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <netdb.h>
#include <optional>
#include <netinet/in.h>
#include <poll.h>
#include <stdexcept>
#include <sys/socket.h>
#include <unistd.h>

namespace graspsim::hw {

ForceSafetyConfig udp_safety_of_model(const std::string& key) {
  const DeviceModel& m = device_model(key);
  ForceSafetyConfig c;
  c.peak_force = m.peak_force;
  c.continuous_force = m.continuous_force;
  return c;
}

// ---- UdpLink --------------------------------------------------------------------------------

UdpLink::UdpLink(double timeout_s, udp::Mode expected) : timeout_s_(timeout_s), expected_(expected) {
  if (!(timeout_s > 0.0) || !std::isfinite(timeout_s)) {
    throw std::invalid_argument("udp device: timeout_s must be a positive number of seconds");
  }
}

void UdpLink::accept(const std::uint8_t* data, std::size_t size) {
  udp::Sample s;
  const udp::DecodeStatus status = udp::decode(data, size, &s);
  if (status != udp::DecodeStatus::kOk) {
    ++counters_.malformed;   // also a valid hello or force: not something a server sends us
    last_refusal_ = status;
    if (!udp::peek_version(data, size, &last_refused_version_)) last_refused_version_ = 0;
    return;
  }
  if (s.mode != expected_) {
    // The server is not what the spec says it is: never use its sample, and remember the
    // first one so the owner stops with a clear error (UdpDevice::read throws).
    if (!mismatch_) mismatch_sequence_ = s.sequence;
    mismatch_ = true;
    return;
  }
  if (has_sample_) {
    // Serial number arithmetic (RFC 1982): newer when the difference, as a signed 32-bit
    // number, is positive, so the order survives the uint32 wrap (49 days at 1 kHz).
    const auto ahead = static_cast<std::int32_t>(s.sequence - newest_.sequence);
    if (ahead <= 0) {
      ++counters_.late;
      return;
    }
    counters_.lost += static_cast<std::uint64_t>(ahead - 1);
  }
  newest_ = s;
  has_sample_ = true;
  fresh_ = true;
  ++counters_.received;
}

DeviceSample UdpLink::read(double time) {
  if (fresh_) {
    fresh_ = false;
    last_fresh_time_ = time;
    lost_ = false;
  } else {
    ++counters_.held;
    if (!lost_ && time - last_fresh_time_ > timeout_s_) {
      lost_ = true;
      ++counters_.link_lost;
    }
  }
  DeviceSample out;
  if (has_sample_) {
    out.position = Vec3(newest_.position[0], newest_.position[1], newest_.position[2]);
    out.gimbal = Vec3(newest_.gimbal[0], newest_.gimbal[1], newest_.gimbal[2]);
    out.buttons = newest_.buttons;
  }
  return out;
}

// ---- UdpDevice ------------------------------------------------------------------------------

namespace {

std::string endpoint(const UdpDeviceConfig& c) { return c.host + ":" + std::to_string(c.port); }

double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

namespace {

ForceSafety checked_safety(const UdpDeviceConfig& c) {
  try {
    return ForceSafety(c.safety);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("udp device " + endpoint(c) + ": " + e.what());
  }
}

std::string newtons(double f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g N", f);
  return buf;
}

}  // namespace

UdpDevice::UdpDevice(const UdpDeviceConfig& config)
    : config_(config),
      link_(config.timeout_s, config.lockstep ? udp::Mode::kLockstep : udp::Mode::kStreaming),
      safety_(checked_safety(config)) {
  const std::string where = "udp device " + endpoint(config);
  if (config.port == 0) throw std::runtime_error(where + ": the server port must be 1 to 65535");
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  const int gai = getaddrinfo(config.host.c_str(), std::to_string(config.port).c_str(), &hints, &found);
  if (gai != 0 || found == nullptr) {
    throw std::runtime_error(where + ": cannot resolve host '" + config.host + "': " + gai_strerror(gai));
  }
  sockaddr_in server{};
  std::memcpy(&server, found->ai_addr, sizeof server);
  freeaddrinfo(found);

  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error(where + ": cannot open a UDP socket: " + std::strerror(errno));
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_addr.s_addr = htonl(INADDR_ANY);
  local.sin_port = htons(config.local_port);
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&local), sizeof local) != 0 ||
      ::connect(fd_, reinterpret_cast<sockaddr*>(&server), sizeof server) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw std::runtime_error(where + ": cannot bind local UDP port " + std::to_string(config.local_port) +
                             " and connect: " + why);
  }
  socklen_t len = sizeof local;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&local), &len);
  local_port_ = ntohs(local.sin_port);
  send_hello();
}

UdpDevice::~UdpDevice() {
  if (fd_ >= 0) ::close(fd_);
}

std::string UdpDevice::describe() const {
  return "udp " + endpoint(config_) + (config_.lockstep ? " (lockstep)" : "") + " (" + config_.model + ": " +
         newtons(config_.safety.peak_force) + " peak, " + newtons(config_.safety.continuous_force) + " continuous)";
}

DeviceLimits UdpDevice::limits() const {
  return DeviceLimits{std::min(config_.limits.max_force, config_.safety.peak_force)};
}

void UdpDevice::send(const std::uint8_t* data, std::size_t size) {
  // A lost datagram is what UDP does; an unreachable server (ECONNREFUSED from an earlier ICMP)
  // shows as samples that stop coming, which the timeout handles. So errors are not fatal here.
  (void)::send(fd_, data, size, MSG_NOSIGNAL);
  ++sent_;
}

void UdpDevice::send_hello() {
  std::uint8_t buf[udp::kHelloSize];
  send(buf, udp::encode(udp::Hello{sent_}, buf));
}

void UdpDevice::drain() {
  // At most this many datagrams per read, so a flooding peer cannot hold a tick forever.
  constexpr int kMaxPerRead = 4096;
  std::uint8_t buf[128];
  for (int i = 0; i < kMaxPerRead; ++i) {
    const ssize_t n = ::recv(fd_, buf, sizeof buf, MSG_TRUNC);   // n = the datagram's real size
    if (n < 0) {
      if (errno == EINTR) continue;
      return;   // EAGAIN: drained; ECONNREFUSED: nothing came
    }
    ++answers_;
    if (static_cast<std::size_t>(n) > sizeof buf) {
      link_.count_malformed();
    } else {
      link_.accept(buf, static_cast<std::size_t>(n));
    }
  }
}

bool UdpDevice::wait_readable(double max_wait_s) {
  pollfd p{fd_, POLLIN, 0};
  const int ms = static_cast<int>(std::ceil(std::max(0.0, max_wait_s) * 1000.0));
  for (;;) {
    const int r = ::poll(&p, 1, ms);
    if (r < 0 && errno == EINTR) continue;
    return r > 0;
  }
}

DeviceSample UdpDevice::read(std::int64_t /*tick*/, double time) {
  // A mismatched server stays refused: never wait for it, never use it.
  if (link_.mode_mismatch()) throw std::runtime_error(mode_mismatch_error());
  if (config_.lockstep) {
    // One answer is owed per datagram sent. Wait for each: a missing one is an error, never a
    // silent hold, so a lockstep run is the same run every time or a clear failure.
    while (answers_ < sent_) {
      if (!wait_readable(config_.answer_wait_s)) {
        throw std::runtime_error("udp device " + endpoint(config_) + " (lockstep): no answer to datagram " +
                                 std::to_string(answers_) + " within " + std::to_string(config_.answer_wait_s) +
                                 " s: is `device_server --lockstep` running at that address?");
      }
      drain();
    }
  }
  drain();
  if (link_.mode_mismatch()) throw std::runtime_error(mode_mismatch_error());
  const DeviceSample s = link_.read(time);
  // Accepted since the previous read (the handshake's samples count at the first read).
  new_samples_ = static_cast<std::int64_t>(link_.counters().received - received_at_read_);
  received_at_read_ = link_.counters().received;
  time_ = time;
  return s;
}

void UdpDevice::output(const Vec3& force) {
  // While the link is lost: zero, and the ramp re-armed for when it comes back. The safety's
  // output() runs on every send, so its heat integrates the force actually sent (zero included).
  if (link_.link_lost())
    safety_.release();
  else
    safety_.request(force, time_);
  last_force_ = safety_.output(time_);
  udp::Force m;
  m.sequence = sent_;
  m.answers = link_.newest().sequence;
  for (int i = 0; i < 3; ++i) m.force[i] = last_force_[i];
  std::uint8_t buf[udp::kForceSize];
  send(buf, udp::encode(m, buf));
}

bool UdpDevice::wait_for_first_sample(double max_wait_s) {
  const double end = wall_now() + max_wait_s;
  double next_hello = wall_now() + 0.25;
  while (!link_.has_sample() && !link_.mode_mismatch()) {
    const double now = wall_now();
    if (now >= end) return false;
    if (now >= next_hello) {
      send_hello();
      next_hello = now + 0.25;
    }
    if (wait_readable(std::min(end, next_hello) - now)) drain();
  }
  return true;
}

bool UdpDevice::wait_for_hello_answer(double max_wait_s) {
  const double end = wall_now() + max_wait_s;
  while (answers_ < sent_) {
    const double now = wall_now();
    if (now >= end) return false;
    if (wait_readable(end - now)) drain();
  }
  return true;
}

std::string UdpDevice::mode_mismatch_error() const {
  const std::string where = endpoint(config_);
  const std::string which = " (its sample " + std::to_string(link_.mismatch_sequence()) + " declared " +
                            udp::describe(link_.expected_mode() == udp::Mode::kLockstep ? udp::Mode::kStreaming
                                                                                         : udp::Mode::kLockstep) +
                            ")";
  if (config_.lockstep) {
    return "udp device " + where + ": the server at " + where +
           " streams samples (a real device?): a lockstep run would not be paced; drop ',lockstep'" + which;
  }
  return "udp device " + where + ": the server at " + where +
         " is a lockstep peer (simulated or replaying: one sample per datagram it receives): a paced run would not "
         "feed it in step; add ',lockstep'" + which;
}

std::string UdpDevice::refusal_note() const {
  const UdpCounters& c = link_.counters();
  if (c.malformed == 0) return "";
  std::string note = "; " + std::to_string(c.malformed) + " datagram(s) refused, the last: ";
  if (link_.last_refusal() == udp::DecodeStatus::kBadVersion) {
    return note + "protocol version " + std::to_string(link_.last_refused_version()) + ", but this graspsim speaks version " +
           std::to_string(udp::kVersion) + " only (update the server: hw/README.md \"UDP protocol\")";
  }
  return note + udp::describe(link_.last_refusal());
}

void UdpDevice::start_up() {
  const std::string where = "udp device " + endpoint(config_);
  if (config_.lockstep) {
    // One answer is owed to the hello: wait for it (no resend, which would be answered too).
    if (!wait_for_hello_answer(config_.answer_wait_s)) {
      throw std::runtime_error(where + " (lockstep): no answer to the hello within " +
                               std::to_string(config_.answer_wait_s) +
                               " s: is `device_server --lockstep` running at that address?");
    }
  } else if (!wait_for_first_sample(config_.handshake_s) && !mode_mismatch()) {
    throw std::runtime_error(where + ": no sample within " + std::to_string(config_.handshake_s) +
                             " s of the hello: is a device server (tools/device_server) running there?" +
                             refusal_note());
  }
  if (mode_mismatch()) throw std::runtime_error(mode_mismatch_error());
  if (!has_sample()) {
    throw std::runtime_error(where + " (lockstep): the answer to the hello is not a sample" + refusal_note());
  }
}

std::unique_ptr<Device> make_udp_device(const UdpDeviceConfig& config) {
  auto device = std::make_unique<UdpDevice>(config);
  if (config.handshake_s > 0.0) device->start_up();
  return device;
}

// ---- parse_udp_spec -------------------------------------------------------------------------

namespace {

bool parse_uint(const std::string& text, unsigned long max, unsigned long* out) {
  if (text.empty() || text.size() > 10 || text.find_first_not_of("0123456789") != std::string::npos) return false;
  const unsigned long v = std::stoul(text);
  if (v > max) return false;
  *out = v;
  return true;
}

}  // namespace

UdpDeviceConfig parse_udp_spec(const std::string& spec_in) {
  const auto fail = [&](const std::string& why) {
    return std::invalid_argument("udp device spec '" + spec_in + "': " + why +
                                 " (expected HOST:PORT[,timeout=S][,local_port=N][,lockstep][,model=KEY]"
                                 "[,max_force=N][,continuous_force=N], e.g. 127.0.0.1:7001,model=premium-1.5)");
  };
  std::string spec = spec_in;
  if (spec.rfind("udp:", 0) == 0) spec = spec.substr(4);
  std::string address = spec.substr(0, spec.find(','));
  std::string options = address.size() < spec.size() ? spec.substr(address.size() + 1) : "";
  const std::size_t colon = address.rfind(':');
  if (colon == std::string::npos) throw fail("no ':PORT'");
  UdpDeviceConfig c;
  c.host = address.substr(0, colon);
  if (c.host.empty()) throw fail("no host before ':'");
  unsigned long port = 0;
  if (!parse_uint(address.substr(colon + 1), 65535, &port) || port == 0) {
    throw fail("port '" + address.substr(colon + 1) + "' is not a number from 1 to 65535");
  }
  c.port = static_cast<std::uint16_t>(port);
  const auto positive = [&](const std::string& key, const std::string& value, const char* unit) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(value, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != value.size() || value.empty() || !(v > 0.0) || !std::isfinite(v)) {
      throw fail(key + " '" + value + "' is not a positive number of " + unit);
    }
    return v;
  };
  std::optional<double> max_force, continuous_force;   // N, explicit: over the model's
  while (!options.empty() || spec.size() > address.size()) {
    const std::string option = options.substr(0, options.find(','));
    options = option.size() < options.size() ? options.substr(option.size() + 1) : "";
    const std::size_t eq = option.find('=');
    const std::string key = option.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : option.substr(eq + 1);
    if (key == "lockstep" && eq == std::string::npos) {
      c.lockstep = true;
    } else if (key == "timeout" && eq != std::string::npos) {
      c.timeout_s = positive(key, value, "seconds");
    } else if (key == "model" && eq != std::string::npos) {
      try {
        c.safety = udp_safety_of_model(value);
      } catch (const std::invalid_argument& e) {
        throw fail(std::string("model: ") + e.what());
      }
      c.model = value;
    } else if (key == "max_force" && eq != std::string::npos) {
      max_force = positive(key, value, "newtons");
    } else if (key == "continuous_force" && eq != std::string::npos) {
      continuous_force = positive(key, value, "newtons");
    } else if (key == "local_port" && eq != std::string::npos) {
      unsigned long local = 0;
      if (!parse_uint(value, 65535, &local)) throw fail("local_port '" + value + "' is not a number from 0 to 65535");
      c.local_port = static_cast<std::uint16_t>(local);
    } else {
      throw fail("unknown option '" + option + "'");
    }
    if (options.empty()) break;
  }
  // Explicit figures replace the model's, whatever the order they were given in.
  if (max_force) c.safety.peak_force = *max_force;
  if (continuous_force) c.safety.continuous_force = *continuous_force;
  if (max_force || continuous_force) c.model += " with " + std::string(max_force ? "max_force" : "") +
                                                (max_force && continuous_force ? ", " : "") +
                                                (continuous_force ? "continuous_force" : "") + " given";
  if (c.safety.continuous_force > c.safety.peak_force) {
    throw fail("continuous_force " + std::to_string(c.safety.continuous_force) + " N is above max_force " +
               std::to_string(c.safety.peak_force) + " N (" + (max_force ? "given" : "of the model") +
               "): the continuous limit cannot exceed the peak");
  }
  return c;
}

}  // namespace graspsim::hw
