// device_server: serves one device over the UDP device protocol (hw/README.md, "UDP protocol"):
// a scripted motion (a line or a circle) or a replay of a trace's /servo hip and gimbal
// columns, streamed at a rate or, with --lockstep, one sample per datagram received (no clock,
// for tests). Every sample declares which of the two this server is (protocol v2), so a client
// never takes a real device's stream for a lockstep peer. It prints the forces it receives. `device_server --help` lists the options.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspsim/hw/udp_protocol.hpp"
#include "graspsim/recordings/trace_reader.hpp"

namespace udp = graspsim::hw::udp;

namespace {

constexpr const char* kHelp = R"(usage: device_server [options]

Serves one device over graspsim's UDP device protocol (hw/README.md, "UDP protocol"): it waits
for a client's hello, then sends samples (position m, gimbal rad, in this server's frame) and
prints the forces (N) it receives.

  --port N            UDP port to listen on (default 7001; 0 = any free port)
  --bind ADDR         local address (default 127.0.0.1; 0.0.0.0 for every interface)
  --rate HZ           samples per second (default 1000; a replay: the trace's rate_servo)
  --lockstep          no clock: answer every hello and force with exactly one datagram, the
                      next sample (a lost one is replaced by a repeat of the last one sent).
                      Every sample declares the mode: lockstep with this option, streaming
                      without (the client's `,lockstep` must match, or it refuses to run)
                      Streaming, the clock starts with the client's run: a hello is answered
                      with sample 0 (at device time 0), and the first force (the run's first
                      tick) starts the clock, so that sample k goes out (k - 1) / rate after it,
                      in time for the run's tick k. A hello from another client starts again
  motion (default: --motion line):
  --motion line       from --from to --to (m, "x,y,z") in --duration s, then hold
  --motion circle     --center "x,y,z" (m), --radius m, --period s, in the x-y plane
  --replay TRACE.h5 --finger NAME
                      row k of /servo/fingers/NAME/hip and /gimbal is sample k; the last row
                      is held after the end
  faults (to test a client):
  --drop-every K      lose every K-th sample (sequence numbers K-1, 2K-1, ...), K >= 2
  --stop-after N      lose every sample after sequence number N
  ending and printing:
  --samples N         exit after N samples (and the datagram that follows the last one)
  --idle-exit S       exit when nothing came for S s of wall time (default: never)
  --print-every N     print every N-th force received (default: one per second of samples)
  --help              this text

Prints "device_server: listening on ADDR:PORT" first (the real port when --port 0). Exit
status 0 at the end, 2 on bad options or an unusable trace or address.
)";

struct Options {
  std::string bind = "127.0.0.1";
  long port = 7001;
  double rate = 0;   // Hz; 0 = default
  bool lockstep = false;
  std::string motion = "line";
  double from[3] = {0.0, 0.0, 0.1}, to[3] = {0.05, 0.0, 0.1};   // m
  double duration = 1.0;                                          // s
  double center[3] = {0.0, 0.0, 0.1};                             // m
  double radius = 0.03;                                           // m
  double period = 2.0;                                            // s
  std::string replay, finger;
  long drop_every = 0, stop_after = -1, samples = 0, print_every = 0;
  double idle_exit = 0;   // s; 0 = never
};

struct Usage : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double number(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v)) {
    throw Usage(option + ": '" + text + "' is not a finite number");
  }
  return v;
}

long integer(const std::string& option, const std::string& text, long min, long max) {
  const double v = number(option, text);
  if (v != std::floor(v) || v < static_cast<double>(min) || v > static_cast<double>(max)) {
    throw Usage(option + ": '" + text + "' is not a whole number from " + std::to_string(min) + " to " +
                std::to_string(max));
  }
  return static_cast<long>(v);
}

void vec3(const std::string& option, const std::string& text, double* out) {
  std::size_t a = text.find(','), b = a == std::string::npos ? a : text.find(',', a + 1);
  if (b == std::string::npos || text.find(',', b + 1) != std::string::npos) {
    throw Usage(option + ": '" + text + "' is not three numbers x,y,z");
  }
  out[0] = number(option, text.substr(0, a));
  out[1] = number(option, text.substr(a + 1, b - a - 1));
  out[2] = number(option, text.substr(b + 1));
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw Usage(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--help" || arg == "-h") {
      std::fputs(kHelp, stdout);
      std::exit(0);
    } else if (arg == "--port") {
      o.port = integer(arg, value(), 0, 65535);
    } else if (arg == "--bind") {
      o.bind = value();
    } else if (arg == "--rate") {
      o.rate = number(arg, value());
      if (!(o.rate > 0)) throw Usage("--rate: must be positive");
    } else if (arg == "--lockstep") {
      o.lockstep = true;
    } else if (arg == "--motion") {
      o.motion = value();
      if (o.motion != "line" && o.motion != "circle") throw Usage("--motion: '" + o.motion + "' is not line or circle");
    } else if (arg == "--from") {
      vec3(arg, value(), o.from);
    } else if (arg == "--to") {
      vec3(arg, value(), o.to);
    } else if (arg == "--duration") {
      o.duration = number(arg, value());
      if (!(o.duration > 0)) throw Usage("--duration: must be positive");
    } else if (arg == "--center") {
      vec3(arg, value(), o.center);
    } else if (arg == "--radius") {
      o.radius = number(arg, value());
    } else if (arg == "--period") {
      o.period = number(arg, value());
      if (!(o.period > 0)) throw Usage("--period: must be positive");
    } else if (arg == "--replay") {
      o.replay = value();
    } else if (arg == "--finger") {
      o.finger = value();
    } else if (arg == "--drop-every") {
      o.drop_every = integer(arg, value(), 2, 1L << 31);
    } else if (arg == "--stop-after") {
      o.stop_after = integer(arg, value(), 0, 0xFFFFFFFEL);
    } else if (arg == "--samples") {
      o.samples = integer(arg, value(), 1, 1L << 40);
    } else if (arg == "--idle-exit") {
      o.idle_exit = number(arg, value());
      if (!(o.idle_exit > 0)) throw Usage("--idle-exit: must be positive");
    } else if (arg == "--print-every") {
      o.print_every = integer(arg, value(), 1, 1L << 40);
    } else {
      throw Usage("unknown option '" + arg + "' (device_server --help)");
    }
  }
  if (o.replay.empty() != o.finger.empty()) throw Usage("--replay and --finger go together");
  return o;
}

// The motion: sample k's position and gimbal at device time t = k / rate.
struct Motion {
  const Options& o;
  std::vector<double> hip, gimbal;   // replay rows, 3 per sample
  void at(std::uint64_t k, double t, udp::Sample* s) const {
    if (!o.replay.empty()) {
      const std::size_t rows = hip.size() / 3;
      const std::size_t r = k < rows ? static_cast<std::size_t>(k) : rows - 1;
      for (int i = 0; i < 3; ++i) {
        s->position[i] = hip[3 * r + i];
        s->gimbal[i] = gimbal[3 * r + i];
      }
    } else if (o.motion == "line") {
      const double u = std::min(t / o.duration, 1.0);
      for (int i = 0; i < 3; ++i) s->position[i] = o.from[i] + (o.to[i] - o.from[i]) * u;
    } else {
      const double a = 2.0 * M_PI * t / o.period;
      s->position[0] = o.center[0] + o.radius * std::cos(a);
      s->position[1] = o.center[1] + o.radius * std::sin(a);
      s->position[2] = o.center[2];
    }
  }
};

std::vector<double> read_rows(const std::string& trace, const std::string& path) {
  if (!graspsim::recordings::has_object(trace, path)) {
    throw Usage(trace + ": no dataset " + path + " (is the finger name right?)");
  }
  const auto d = graspsim::recordings::read_dataset(trace, path);
  if (d.shape.size() != 2 || d.shape[1] != 3 || d.shape[0] == 0) {
    throw Usage(trace + ": " + path + " is not a non-empty (n, 3) dataset");
  }
  for (double v : d.values) {
    if (!std::isfinite(v)) throw Usage(trace + ": " + path + " holds a non-finite number");
  }
  return d.values;
}

double monotonic() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int serve(const Options& o) {
  Motion motion{o, {}, {}};
  double rate = o.rate;
  if (!o.replay.empty()) {
    if (access(o.replay.c_str(), R_OK) != 0) throw Usage(o.replay + ": no such readable file");
    motion.hip = read_rows(o.replay, "/servo/fingers/" + o.finger + "/hip");
    motion.gimbal = read_rows(o.replay, "/servo/fingers/" + o.finger + "/gimbal");
    if (motion.hip.size() != motion.gimbal.size()) throw Usage(o.replay + ": hip and gimbal differ in length");
    if (rate == 0 && graspsim::recordings::has_attribute(o.replay, "/", "rate_servo")) {
      rate = static_cast<double>(graspsim::recordings::read_int_attribute(o.replay, "/", "rate_servo"));
    }
  }
  if (rate == 0) rate = 1000.0;

  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_port = htons(static_cast<std::uint16_t>(o.port));
  if (inet_pton(AF_INET, o.bind.c_str(), &local.sin_addr) != 1) throw Usage("--bind: '" + o.bind + "' is not an IPv4 address");
  if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&local), sizeof local) != 0) {
    throw Usage("cannot listen on " + o.bind + ":" + std::to_string(o.port) + ": " + std::strerror(errno));
  }
  socklen_t len = sizeof local;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &len);
  std::printf("device_server: listening on %s:%u (%s, %g Hz), %s\n", o.bind.c_str(), ntohs(local.sin_port),
              o.lockstep ? "lockstep" : "streaming", rate,
              o.replay.empty() ? ("motion " + o.motion).c_str() : ("replay of " + o.replay + " finger " + o.finger).c_str());
  std::fflush(stdout);

  const long print_every = o.print_every > 0 ? o.print_every : std::max(1L, std::lround(rate));
  sockaddr_in client{};
  bool have_client = false;
  std::uint64_t k = 0, forces = 0, hellos = 0, malformed = 0, sent = 0, lost = 0;
  udp::Sample last_sent;
  bool any_sent = false;
  // Streaming: the device's clock (s, monotonic) at sample 0; running once the first force came.
  double start = monotonic();
  bool clock_running = false;
  double last_heard = start;

  const auto lost_sample = [&](std::uint64_t seq) {
    return (o.drop_every > 0 && seq % o.drop_every == static_cast<std::uint64_t>(o.drop_every - 1)) ||
           (o.stop_after >= 0 && seq > static_cast<std::uint64_t>(o.stop_after));
  };
  // Produces sample k; sends it (or, if lost, in lockstep a repeat of the last one sent).
  const auto produce = [&](double device_time) {
    udp::Sample s;
    s.sequence = static_cast<std::uint32_t>(k);
    s.device_time = device_time;
    s.mode = o.lockstep ? udp::Mode::kLockstep : udp::Mode::kStreaming;
    motion.at(k, device_time, &s);
    ++k;
    std::uint8_t b[udp::kSampleSize];
    if (lost_sample(s.sequence)) {
      ++lost;
      if (!o.lockstep) return;
      s = any_sent ? last_sent : s;   // stand-in so the client still gets one answer
      if (!any_sent) return;
    } else {
      last_sent = s;
      any_sent = true;
    }
    ::sendto(fd, b, udp::encode(s, b), 0, reinterpret_cast<sockaddr*>(&client), sizeof client);
    ++sent;
  };
  // Handles one datagram; true if it asks for an answer (a hello or a force).
  const auto handle = [&](const std::uint8_t* b, ssize_t n, const sockaddr_in& from) {
    last_heard = monotonic();
    udp::MessageType type;
    if (n < 0 || udp::peek_type(b, static_cast<std::size_t>(n), &type) != udp::DecodeStatus::kOk) {
      ++malformed;
      return false;
    }
    if (type == udp::MessageType::kHello) {
      udp::Hello h;
      if (udp::decode(b, static_cast<std::size_t>(n), &h) != udp::DecodeStatus::kOk) return ++malformed, false;
      const bool other = have_client && (from.sin_addr.s_addr != client.sin_addr.s_addr || from.sin_port != client.sin_port);
      if (!o.lockstep && other) {
        k = 0;   // another client's run: the playback starts again
        any_sent = false;
        clock_running = false;
      }
      client = from;
      have_client = true;
      ++hellos;
      if (!o.lockstep && !clock_running) {
        // The handshake: sample 0, again for a repeated hello (the client resends until one comes).
        if (k == 0) produce(0.0);
        else if (any_sent) {
          std::uint8_t again[udp::kSampleSize];
          ::sendto(fd, again, udp::encode(last_sent, again), 0, reinterpret_cast<const sockaddr*>(&client), sizeof client);
        }
      }
      return true;
    }
    udp::Force f;
    if (type != udp::MessageType::kForce || udp::decode(b, static_cast<std::size_t>(n), &f) != udp::DecodeStatus::kOk) {
      ++malformed;
      return false;
    }
    if (!have_client) return false;   // a force before any hello: nobody to answer
    if (!o.lockstep && !clock_running) {
      // The run's tick 0 has read sample 0 and sent this force: sample 1 is due now, for tick 1.
      start = monotonic() - 1.0 / rate;
      clock_running = true;
    }
    ++forces;
    if (forces % print_every == 0) {
      std::printf("force seq=%u answers=%u F=%.17g,%.17g,%.17g N\n", f.sequence, f.answers, f.force[0], f.force[1],
                  f.force[2]);
      std::fflush(stdout);
    }
    return true;
  };
  const auto finished = [&] { return o.samples > 0 && k >= static_cast<std::uint64_t>(o.samples); };

  std::uint8_t buf[512];
  for (;;) {
    const double now = monotonic();
    if (o.idle_exit > 0 && now - last_heard > o.idle_exit) {
      std::printf("device_server: nothing received for %g s: exiting\n", o.idle_exit);
      break;
    }
    // Lockstep waits for the next datagram; streaming polls until the next sample is due.
    const double due = start + static_cast<double>(k) / rate;
    const bool streaming = !o.lockstep && have_client && clock_running;
    const double wait = streaming ? std::max(0.0, due - now) : 0.1;
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(std::ceil(wait * 1000.0))) > 0) {
      sockaddr_in from{};
      socklen_t flen = sizeof from;
      const ssize_t n = ::recvfrom(fd, buf, sizeof buf, MSG_TRUNC, reinterpret_cast<sockaddr*>(&from), &flen);
      const bool answer = handle(buf, n > static_cast<ssize_t>(sizeof buf) ? -1 : n, from);
      if (o.lockstep && answer) {
        if (finished()) break;
        produce(static_cast<double>(k) / rate);
      }
      continue;
    }
    if (streaming && monotonic() >= due) {
      if (finished()) break;
      produce(monotonic() - start);
    }
  }
  std::printf("device_server: %llu samples (%llu lost, %llu datagrams sent), %llu forces, %llu hellos, %llu malformed\n",
              static_cast<unsigned long long>(k), static_cast<unsigned long long>(lost),
              static_cast<unsigned long long>(sent), static_cast<unsigned long long>(forces),
              static_cast<unsigned long long>(hellos), static_cast<unsigned long long>(malformed));
  ::close(fd);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return serve(parse(argc, argv));
  } catch (const Usage& e) {
    std::fprintf(stderr, "device_server: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "device_server: %s\n", e.what());
    return 2;
  }
}
