// The UDP device protocol (hw/README.md, "UDP protocol"): every message survives a round trip
// bit for bit, the bytes are where the README's table says, and every kind of malformed
// datagram is refused with its reason (and `out` left untouched).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "graspsim/hw/udp_protocol.hpp"

namespace udp = graspsim::hw::udp;
using udp::DecodeStatus;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

udp::Sample awkward_sample() {
  // Every mantissa bit in use, a -0, a denormal, the largest double and the largest uint32.
  udp::Sample s;
  s.sequence = 0xFFFFFFFFu;
  s.buttons = 0x80000001u;
  s.device_time = 1.0 / 3.0;
  s.position[0] = -0.0;
  s.position[1] = 4.9e-324;
  s.position[2] = std::numeric_limits<double>::max();
  s.gimbal[0] = std::nextafter(0.2, 1.0);
  s.gimbal[1] = -std::acos(-1.0);
  s.gimbal[2] = -1e-300;
  s.mode = udp::Mode::kLockstep;   // not the default
  return s;
}

}  // namespace

TEST_CASE("UDP protocol: hello, sample and force round trip bit for bit", "[hw][udp][protocol]") {
  std::uint8_t buf[udp::kMaxDatagram];
  const udp::Sample s = awkward_sample();
  REQUIRE(udp::encode(s, buf) == udp::kSampleSize);
  udp::Sample s2;
  REQUIRE(udp::decode(buf, udp::kSampleSize, &s2) == DecodeStatus::kOk);
  CHECK(s2.sequence == s.sequence);
  CHECK(s2.buttons == s.buttons);
  CHECK(same_bits(s2.device_time, s.device_time));
  for (int i = 0; i < 3; ++i) {
    CHECK(same_bits(s2.position[i], s.position[i]));
    CHECK(same_bits(s2.gimbal[i], s.gimbal[i]));
  }
  CHECK(s2.mode == udp::Mode::kLockstep);
  for (const udp::Mode mode : {udp::Mode::kStreaming, udp::Mode::kLockstep}) {   // both modes survive
    udp::Sample m = awkward_sample();
    m.mode = mode;
    udp::encode(m, buf);
    udp::Sample m2;
    REQUIRE(udp::decode(buf, udp::kSampleSize, &m2) == DecodeStatus::kOk);
    CHECK(m2.mode == mode);
  }

  udp::Force f;
  f.sequence = 7;
  f.answers = 0xFFFFFFFEu;
  f.force[0] = -0.0;
  f.force[1] = 1.0 / 7.0;
  f.force[2] = -8.5;
  REQUIRE(udp::encode(f, buf) == udp::kForceSize);
  udp::Force f2;
  REQUIRE(udp::decode(buf, udp::kForceSize, &f2) == DecodeStatus::kOk);
  CHECK(f2.sequence == 7);
  CHECK(f2.answers == 0xFFFFFFFEu);
  for (int i = 0; i < 3; ++i) CHECK(same_bits(f2.force[i], f.force[i]));

  REQUIRE(udp::encode(udp::Hello{123456789u}, buf) == udp::kHelloSize);
  udp::Hello h;
  REQUIRE(udp::decode(buf, udp::kHelloSize, &h) == DecodeStatus::kOk);
  CHECK(h.sequence == 123456789u);
}

TEST_CASE("UDP protocol: the bytes are little-endian at the documented offsets", "[hw][udp][protocol]") {
  // The README's table, pinned: a server written from the table alone must interoperate.
  udp::Sample s;
  s.sequence = 0x04030201u;
  s.buttons = 0x0A;
  s.device_time = 1.0;   // IEEE 754: 0x3FF0000000000000
  s.position[0] = 2.0;   // 0x4000000000000000
  s.gimbal[2] = -2.0;    // 0xC000000000000000
  s.mode = udp::Mode::kLockstep;   // 2
  std::uint8_t b[udp::kSampleSize];
  CHECK(udp::kSampleSize == 80);
  udp::encode(s, b);
  CHECK(std::vector<std::uint8_t>(b, b + 8) == std::vector<std::uint8_t>{'G', 'S', 'D', 'V', 2, 0, 2, 0});
  CHECK(std::vector<std::uint8_t>(b + 8, b + 16) == std::vector<std::uint8_t>{1, 2, 3, 4, 0x0A, 0, 0, 0});
  CHECK(b[16 + 7] == 0x3F);
  CHECK(b[16 + 6] == 0xF0);
  CHECK(b[24 + 7] == 0x40);
  CHECK(b[48 + 16 + 7] == 0xC0);
  CHECK(b[48 + 16 + 6] == 0x00);
  // v2: the mode at 72-75 (1 streaming, 2 lockstep), reserved zero at 76-79.
  CHECK(std::vector<std::uint8_t>(b + 72, b + 80) == std::vector<std::uint8_t>{2, 0, 0, 0, 0, 0, 0, 0});
  s.mode = udp::Mode::kStreaming;
  udp::encode(s, b);
  CHECK(std::vector<std::uint8_t>(b + 72, b + 80) == std::vector<std::uint8_t>{1, 0, 0, 0, 0, 0, 0, 0});

  udp::Force f;
  f.sequence = 5;
  f.answers = 0x0100;
  f.force[2] = 1.0;
  std::uint8_t c[udp::kForceSize];
  udp::encode(f, c);
  CHECK(std::vector<std::uint8_t>(c, c + 16) ==
        std::vector<std::uint8_t>{'G', 'S', 'D', 'V', 2, 0, 3, 0, 5, 0, 0, 0, 0, 1, 0, 0});
  CHECK(c[16 + 16 + 7] == 0x3F);

  std::uint8_t h[udp::kHelloSize];
  udp::encode(udp::Hello{9}, h);
  CHECK(std::vector<std::uint8_t>(h, h + 16) ==
        std::vector<std::uint8_t>{'G', 'S', 'D', 'V', 2, 0, 1, 0, 9, 0, 0, 0, 0, 0, 0, 0});
}

TEST_CASE("UDP protocol: every wrong size is refused", "[hw][udp][protocol]") {
  std::uint8_t good[udp::kMaxDatagram + 8] = {};
  udp::encode(awkward_sample(), good);
  udp::Sample out;
  out.sequence = 42;   // a refused datagram leaves `out` as it was
  for (std::size_t n = 0; n <= sizeof good; ++n) {
    const DecodeStatus st = udp::decode(good, n, &out);
    if (n == udp::kSampleSize) {
      CHECK(st == DecodeStatus::kOk);
      out.sequence = 42;
    } else {
      INFO("size " << n);
      CHECK(st == (n < udp::kHeaderSize ? DecodeStatus::kTooShort : DecodeStatus::kBadSize));
      CHECK(out.sequence == 42);
    }
  }
  CHECK(udp::decode(nullptr, udp::kSampleSize, &out) == DecodeStatus::kTooShort);
  std::uint8_t force[udp::kForceSize];
  udp::encode(udp::Force{}, force);
  udp::Force f;
  CHECK(udp::decode(force, udp::kForceSize - 1, &f) == DecodeStatus::kBadSize);
  CHECK(udp::decode(force, udp::kForceSize, &f) == DecodeStatus::kOk);
}

TEST_CASE("UDP protocol: wrong magic, version or type is refused", "[hw][udp][protocol]") {
  std::uint8_t b[udp::kSampleSize];
  udp::Sample out;
  for (int i = 0; i < 4; ++i) {   // any one magic byte off
    udp::encode(awkward_sample(), b);
    b[i] ^= 0x20;
    CHECK(udp::decode(b, sizeof b, &out) == DecodeStatus::kBadMagic);
  }
  for (std::uint16_t version : {0, 1, 3, 0x0100, 0x0200, 0xFFFF}) {
    udp::encode(awkward_sample(), b);
    b[4] = static_cast<std::uint8_t>(version);
    b[5] = static_cast<std::uint8_t>(version >> 8);
    INFO("version " << version);
    CHECK(udp::decode(b, sizeof b, &out) == DecodeStatus::kBadVersion);
  }
  for (std::uint16_t type : {0, 4, 0x0200, 0xFFFF}) {
    udp::encode(awkward_sample(), b);
    b[6] = static_cast<std::uint8_t>(type);
    b[7] = static_cast<std::uint8_t>(type >> 8);
    INFO("type " << type);
    CHECK(udp::decode(b, sizeof b, &out) == DecodeStatus::kBadType);
  }
  // A well-formed message of another type is not a sample (and its size is never looked at).
  std::uint8_t f[udp::kForceSize];
  udp::encode(udp::Force{}, f);
  CHECK(udp::decode(f, sizeof f, &out) == DecodeStatus::kBadType);
  udp::Hello h;
  CHECK(udp::decode(b, 0, &h) == DecodeStatus::kTooShort);
  udp::encode(awkward_sample(), b);
  CHECK(udp::decode(b, udp::kHelloSize, &h) == DecodeStatus::kBadType);
  udp::MessageType t;
  CHECK(udp::peek_type(b, sizeof b, &t) == DecodeStatus::kOk);
  CHECK(t == udp::MessageType::kSample);
}

TEST_CASE("UDP protocol: a NaN or infinity in any number is refused", "[hw][udp][protocol]") {
  const double bad[] = {std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN(),
                        std::numeric_limits<double>::signaling_NaN(), std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity()};
  // Sample: device time, 3 position and 3 gimbal doubles; put each bad value in each of them.
  for (int field = 0; field < 7; ++field) {
    for (double v : bad) {
      udp::Sample s = awkward_sample();
      double* slots[] = {&s.device_time, &s.position[0], &s.position[1], &s.position[2],
                         &s.gimbal[0],   &s.gimbal[1],   &s.gimbal[2]};
      *slots[field] = v;
      std::uint8_t b[udp::kSampleSize];
      udp::encode(s, b);
      udp::Sample out;
      out.sequence = 42;
      INFO("sample double " << field << " = " << v);
      CHECK(udp::decode(b, sizeof b, &out) == DecodeStatus::kNotFinite);
      CHECK(out.sequence == 42);
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (double v : bad) {
      udp::Force f;
      f.force[axis] = v;
      std::uint8_t b[udp::kForceSize];
      udp::encode(f, b);
      udp::Force out;
      INFO("force " << axis << " = " << v);
      CHECK(udp::decode(b, sizeof b, &out) == DecodeStatus::kNotFinite);
    }
  }
  CHECK(std::string(udp::describe(DecodeStatus::kNotFinite)) == "a NaN or infinite number");
}

namespace {

// A version-1 sample as a v1 server sends it (the v1 table of hw/README.md): 72 bytes, version
// 1, no mode. Written here byte by byte, not with encode, which only speaks the current version.
std::vector<std::uint8_t> v1_sample() {
  std::vector<std::uint8_t> b(72, 0);
  const std::uint8_t header[8] = {'G', 'S', 'D', 'V', 1, 0, 2, 0};
  std::memcpy(b.data(), header, 8);
  b[8] = 7;      // sequence 7
  b[23] = 0x3F;  // device time 1.0 s: 0x3FF0000000000000
  b[22] = 0xF0;
  return b;
}

}  // namespace

TEST_CASE("UDP protocol v2: a version 1 datagram is refused naming both versions", "[hw][udp][protocol]") {
  // A v1 sample is refused for its version (checked before its size, so the reason is the
  // version, not the 72 bytes), whatever size it is sent with.
  std::vector<std::uint8_t> v1 = v1_sample();
  udp::Sample out;
  out.sequence = 42;
  CHECK(udp::decode(v1.data(), v1.size(), &out) == DecodeStatus::kBadVersion);
  v1.resize(udp::kSampleSize, 0);   // even padded to v2's size
  CHECK(udp::decode(v1.data(), v1.size(), &out) == DecodeStatus::kBadVersion);
  CHECK(out.sequence == 42);
  std::uint16_t version = 0;
  REQUIRE(udp::peek_version(v1.data(), v1.size(), &version));
  CHECK(version == 1);
  CHECK(!udp::peek_version(v1.data(), 7, &version));
  v1[0] = 'X';
  CHECK(!udp::peek_version(v1.data(), v1.size(), &version));
  CHECK(std::string(udp::describe(DecodeStatus::kBadVersion)).find("version 2") != std::string::npos);
  CHECK(udp::kVersion == 2);
  // v1 hellos and forces too: a v2 server refuses a v1 client.
  const std::uint8_t hello[16] = {'G', 'S', 'D', 'V', 1, 0, 1, 0};
  udp::Hello h;
  CHECK(udp::decode(hello, sizeof hello, &h) == DecodeStatus::kBadVersion);
}

TEST_CASE("UDP protocol v2: a sample without a valid mode is refused", "[hw][udp][protocol]") {
  // The mode is never guessed: 0 (a server that forgot to declare), any other number, or a
  // nonzero reserved word is refused, and `out` is left as it was.
  std::uint8_t b[udp::kSampleSize];
  udp::Sample out;
  out.sequence = 42;
  for (const std::uint32_t mode : {0u, 3u, 0x100u, 0x80000001u, 0xFFFFFFFFu}) {
    udp::encode(awkward_sample(), b);
    for (int i = 0; i < 4; ++i) b[72 + i] = static_cast<std::uint8_t>(mode >> (8 * i));
    INFO("mode " << mode);
    CHECK(udp::decode(b, sizeof b, &out) == DecodeStatus::kBadMode);
  }
  for (int byte = 76; byte < 80; ++byte) {
    udp::encode(awkward_sample(), b);
    b[byte] = 1;
    INFO("reserved byte " << byte);
    CHECK(udp::decode(b, sizeof b, &out) == DecodeStatus::kBadMode);
  }
  CHECK(out.sequence == 42);
  for (const std::uint8_t mode : {1, 2}) {   // the two valid ones
    udp::encode(awkward_sample(), b);
    b[72] = mode;
    CHECK(udp::decode(b, sizeof b, &out) == DecodeStatus::kOk);
    CHECK(static_cast<std::uint32_t>(out.mode) == mode);
  }
  CHECK(std::string(udp::describe(udp::Mode::kStreaming)) == "streaming");
  CHECK(std::string(udp::describe(udp::Mode::kLockstep)) == "lockstep");
}
