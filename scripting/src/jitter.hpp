// Perturbed waypoints (LoadOptions::jitter, `graspsim run --jitter A --jitter-seed N`): each
// finger's trajectory moved by random offsets, uniform in [-A, A) per axis, from a generator that
// is the same on every machine and standard library (splitmix64 and an explicit uniform mapping,
// not <random>'s distributions nor Lua's math.random).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "graspsim/hw/trajectory.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::scripting::detail {

// splitmix64 (Steele, Lea & Flood, "Fast splittable pseudorandom number generators", OOPSLA
// 2014; Vigna's reference code): a 64-bit counter stepped by the golden ratio and mixed. Every
// seed gives a full-period stream; integer operations only, so the stream is exact everywhere.
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1): the top 53 bits of one draw times 2^-53 (exact).
  double uniform01() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  // Uniform in [-a, a): a (2u - 1); 2u - 1 is exact, so one rounding in all.
  double symmetric(double a) { return a * (2.0 * uniform01() - 1.0); }

 private:
  std::uint64_t state_;
};

// The `count` offsets (m, world) of finger `finger` (Model::fingers index): x, y, z of offset 0,
// then of offset 1, ... Each finger draws from its own stream, seeded by the finger-th output
// (0-based) of a splitmix64 seeded with jitter.seed, so a finger's offsets do not depend on how
// many waypoints the fingers before it have.
std::vector<Vec3> jitter_offsets(const Jitter& jitter, std::size_t finger, std::size_t count);

// A trajectory moved by a constant offset: the jitter of a trajectory given as a function (a
// feedback controller has no waypoints to move). The gimbal is passed through.
class OffsetTrajectory final : public hw::Trajectory {
 public:
  OffsetTrajectory(std::unique_ptr<hw::Trajectory> inner, const Vec3& offset)
      : inner_(std::move(inner)), offset_(offset) {}
  hw::TrajectorySample sample(double t) override {
    hw::TrajectorySample s = inner_->sample(t);
    s.position += offset_;
    return s;
  }

 private:
  std::unique_ptr<hw::Trajectory> inner_;
  Vec3 offset_;   // m, world
};

}  // namespace graspsim::scripting::detail
