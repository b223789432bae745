// state_hash: an FNV-1a-style hash over the State's fields, one 64-bit word per step (xor,
// multiply by the FNV-1a 64 prime, xor-shift by 32), in declaration order.
#include "graspsim/engine/state_hash.hpp"

#include <bit>

namespace graspsim {
namespace {

// A new field in one of these structs must be hashed below (and mutated in
// tests/engine/test_state_hash.cpp): these sizes trip when the layout changes.
#if defined(__x86_64__) && defined(__GNUC__)
static_assert(sizeof(State) == 80, "State changed: update state_hash and its test");
static_assert(sizeof(BodyState) == 392, "BodyState changed: update state_hash and its test");
static_assert(sizeof(VertexContact) == 56, "VertexContact changed: update state_hash and its test");
static_assert(sizeof(FingerState) == 240, "FingerState changed: update state_hash and its test");
static_assert(sizeof(Features) == 16, "Features changed: update state_hash and its test");
static_assert(sizeof(PairContact) == 1040, "PairContact changed: update state_hash and its test");
static_assert(sizeof(PairPointContact) == 64, "PairPointContact changed: update state_hash and its test");
#endif

class Hasher {
 public:
  // One 64-bit word per step (8 times fewer multiplies than feeding its bytes, which would make
  // the hash the largest logging cost at 3 kHz physics): FNV-1a's xor and multiply on the whole
  // word, then an xor-shift. The multiply only carries a bit upward, so without the shift a
  // difference in a word's top bit (a sign) would stay in the top bit, and two of them (x and
  // y both negated) would cancel; the shift folds the top half down before the next word.
  void word(std::uint64_t w) {
    hash_ ^= w;
    hash_ *= kFnv1a64Prime;
    hash_ ^= hash_ >> 32;
  }
  void real(double x) { word(std::bit_cast<std::uint64_t>(x)); }
  void integer(std::int64_t i) { word(static_cast<std::uint64_t>(i)); }
  void flag(bool b) { word(b ? 1u : 0u); }
  void size(std::size_t n) { word(static_cast<std::uint64_t>(n)); }
  void vec(const Vec3& v) {
    real(v.x());
    real(v.y());
    real(v.z());
  }
  void mat(const Mat3& m) {   // row by row
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) real(m(r, c));
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = kFnv1a64Offset;
};

}  // namespace

std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t hash) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= kFnv1a64Prime;
  }
  return hash;
}

std::uint64_t state_hash(const State& s) {
  Hasher h;
  h.integer(s.tick);
  h.size(s.bodies.size());
  for (const BodyState& b : s.bodies) {
    h.vec(b.position);
    h.mat(b.rotation);
    h.vec(b.velocity);
    h.vec(b.angular_velocity);
    h.vec(b.position_before_step);
    h.mat(b.rotation_before_step);
    h.integer(b.stepped_at);
    h.size(b.floor_contacts.size());
    for (const VertexContact& v : b.floor_contacts) {
      h.flag(v.active);
      h.flag(v.slipping);
      h.vec(v.anchor);
      h.vec(v.material);
    }
    h.vec(b.window_force);
    h.vec(b.window_torque);
    // The second-order history, only when there is one: the paper's step keeps its hashes.
    if (b.island_signature != 0) {
      h.vec(b.velocity_before_step);
      h.vec(b.angular_velocity_before_step);
      h.integer(static_cast<std::int64_t>(b.island_signature));
      h.integer(b.island_steps);
    }
    // Sleep, only when not at its defaults: a run without sleep keeps its hashes (and goldens).
    if (b.asleep || b.still_steps != 0) {
      h.flag(b.asleep);
      h.integer(b.still_steps);
    }
  }
  h.size(s.fingers.size());
  for (const FingerState& f : s.fingers) {
    h.vec(f.hip_at_last_servo);
    h.vec(f.hip_at_last_haptic);
    h.flag(f.has_last_haptic);
    h.integer(static_cast<std::int64_t>(f.phase));
    h.integer(f.body);
    h.integer(f.features.count);
    for (int id : f.features.ids) h.integer(id);   // all kMaxFeatures, used or not
    h.vec(f.surface_point);
    h.vec(f.normal);
    h.vec(f.god_object);
    h.real(f.viscous_force);
    h.real(f.friction_mu);
    h.real(f.friction_radius);
    h.real(f.pitch_at_last_physics);
    h.flag(f.has_pitch);
    // Only once set (implicit integrator), so that a paper trace's hash does not depend on these
    // fields (the goldens hold the paper's scheme).
    if (f.has_last_physics) {
      h.flag(f.has_last_physics);
      h.vec(f.hip_at_last_physics);
      h.vec(f.window_force);
    }
  }
  h.size(s.pairs.size());
  for (const PairContact& p : s.pairs) {
    h.integer(p.a);
    h.integer(p.b);
    h.integer(p.count);
    for (int i = 0; i < p.count; ++i) {   // the points in use: a pair's list holds no others
      const PairPointContact& q = p.points[i];
      h.word(q.key);
      h.flag(q.slipping);
      h.vec(q.anchor_a);
      h.vec(q.anchor_b);
    }
  }
  return h.value();
}

}  // namespace graspsim
