// state_hash: a fingerprint of the whole State. The law: equal States (bit for bit) hash equal;
// a State that differs in any one field, in any one bit pattern (even -0.0 against 0.0), hashes
// differently. The mutations below are written out field by field, independently of the hash's
// own traversal, so a field the hash forgets makes this test fail.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "graspsim/engine/state_hash.hpp"
#include "tests/engine/harness.hpp"

using namespace graspsim;

namespace {

// A State with 2 bodies (2 floor points each), 2 fingers and their one pair, every value distinct.
State sample_state() {
  State s;
  double v = 0.125;
  const auto next = [&v] { return v += 0.5; };
  const auto vec = [&] { return Vec3(next(), next(), next()); };
  const auto mat = [&] {
    Mat3 m;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m(r, c) = next();
    return m;
  };
  s.tick = 12345;
  s.bodies.resize(2);
  for (BodyState& b : s.bodies) {
    b.position = vec();
    b.rotation = mat();
    b.velocity = vec();
    b.angular_velocity = vec();
    b.position_before_step = vec();
    b.rotation_before_step = mat();
    b.stepped_at = 12300;
    b.velocity_before_step = vec();
    b.angular_velocity_before_step = vec();
    b.island_signature = 0x5eed;
    b.floor_contacts.resize(2);
    for (VertexContact& c : b.floor_contacts) {
      c.active = true;
      c.slipping = false;
      c.anchor = vec();
      c.material = vec();
    }
    b.window_force = vec();
    b.window_torque = vec();
  }
  s.bodies[1].still_steps = 3;
  s.fingers.resize(2);
  for (FingerState& f : s.fingers) {
    f.hip_at_last_servo = vec();
    f.hip_at_last_haptic = vec();
    f.has_last_haptic = true;
    f.phase = ContactPhase::kStick;
    f.body = 1;
    f.features.count = 2;
    f.features.ids = {4, 2, 7};
    f.surface_point = vec();
    f.normal = vec();
    f.god_object = vec();
    f.viscous_force = next();
    f.friction_mu = next();
    f.friction_radius = next();
    f.pitch_at_last_physics = next();
    f.has_pitch = true;
    f.hip_at_last_physics = vec();
    f.window_force = vec();
    f.has_last_physics = true;
  }
  s.pairs.resize(1);
  s.pairs[0].a = 0;
  s.pairs[0].b = 1;
  s.pairs[0].count = kMaxPairPoints;   // every point in use, so that each is hashed
  std::uint64_t key = 1000;
  for (PairPointContact& p : s.pairs[0].points) {
    p.key = ++key;
    p.slipping = true;
    p.anchor_a = vec();
    p.anchor_b = vec();
  }
  return s;
}

using Mutation = std::pair<std::string, std::function<void(State&)>>;

// One mutation per scalar of every field (each component of a vector or matrix on its own).
std::vector<Mutation> mutations() {
  std::vector<Mutation> m;
  const auto add = [&m](std::string name, std::function<void(State&)> f) {
    m.emplace_back(std::move(name), std::move(f));
  };
  const auto add_vec = [&](const std::string& name, std::function<Vec3&(State&)> get) {
    for (int i = 0; i < 3; ++i)
      add(name + "[" + std::to_string(i) + "]", [get, i](State& s) { get(s)[i] += 1.0; });
  };
  const auto add_mat = [&](const std::string& name, std::function<Mat3&(State&)> get) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        add(name + "(" + std::to_string(r) + "," + std::to_string(c) + ")",
            [get, r, c](State& s) { get(s)(r, c) += 1.0; });
  };
  add("tick", [](State& s) { ++s.tick; });
  for (int b = 0; b < 2; ++b) {
    const std::string p = "bodies[" + std::to_string(b) + "].";
    add_vec(p + "position", [b](State& s) -> Vec3& { return s.bodies[b].position; });
    add_mat(p + "rotation", [b](State& s) -> Mat3& { return s.bodies[b].rotation; });
    add_vec(p + "velocity", [b](State& s) -> Vec3& { return s.bodies[b].velocity; });
    add_vec(p + "angular_velocity", [b](State& s) -> Vec3& { return s.bodies[b].angular_velocity; });
    add_vec(p + "position_before_step", [b](State& s) -> Vec3& { return s.bodies[b].position_before_step; });
    add_mat(p + "rotation_before_step", [b](State& s) -> Mat3& { return s.bodies[b].rotation_before_step; });
    add(p + "stepped_at", [b](State& s) { ++s.bodies[b].stepped_at; });
    add_vec(p + "velocity_before_step", [b](State& s) -> Vec3& { return s.bodies[b].velocity_before_step; });
    add_vec(p + "angular_velocity_before_step", [b](State& s) -> Vec3& { return s.bodies[b].angular_velocity_before_step; });
    add(p + "island_signature", [b](State& s) { ++s.bodies[b].island_signature; });
    add(p + "island_steps", [b](State& s) { ++s.bodies[b].island_steps; });
    for (int k = 0; k < 2; ++k) {
      const std::string q = p + "floor_contacts[" + std::to_string(k) + "].";
      add(q + "active", [b, k](State& s) { s.bodies[b].floor_contacts[k].active ^= true; });
      add(q + "slipping", [b, k](State& s) { s.bodies[b].floor_contacts[k].slipping ^= true; });
      add_vec(q + "anchor", [b, k](State& s) -> Vec3& { return s.bodies[b].floor_contacts[k].anchor; });
      add_vec(q + "material", [b, k](State& s) -> Vec3& { return s.bodies[b].floor_contacts[k].material; });
    }
    add(p + "floor_contacts (one more)", [b](State& s) { s.bodies[b].floor_contacts.emplace_back(); });
    add_vec(p + "window_force", [b](State& s) -> Vec3& { return s.bodies[b].window_force; });
    add_vec(p + "window_torque", [b](State& s) -> Vec3& { return s.bodies[b].window_torque; });
    // Body 0 has sleep at its defaults (hashed only when set), body 1 is counting towards sleep.
    add(p + "asleep", [b](State& s) { s.bodies[b].asleep ^= true; });
    add(p + "still_steps", [b](State& s) { ++s.bodies[b].still_steps; });
  }
  add("bodies (one more)", [](State& s) { s.bodies.emplace_back(); });
  for (int f = 0; f < 2; ++f) {
    const std::string p = "fingers[" + std::to_string(f) + "].";
    add_vec(p + "hip_at_last_servo", [f](State& s) -> Vec3& { return s.fingers[f].hip_at_last_servo; });
    add_vec(p + "hip_at_last_haptic", [f](State& s) -> Vec3& { return s.fingers[f].hip_at_last_haptic; });
    add(p + "has_last_haptic", [f](State& s) { s.fingers[f].has_last_haptic ^= true; });
    add(p + "phase", [f](State& s) { s.fingers[f].phase = ContactPhase::kSlip; });
    add(p + "body", [f](State& s) { s.fingers[f].body = kFloor; });
    add(p + "features.count", [f](State& s) { s.fingers[f].features.count = 3; });
    for (int i = 0; i < kMaxFeatures; ++i)
      add(p + "features.ids[" + std::to_string(i) + "]", [f, i](State& s) { ++s.fingers[f].features.ids[i]; });
    add_vec(p + "surface_point", [f](State& s) -> Vec3& { return s.fingers[f].surface_point; });
    add_vec(p + "normal", [f](State& s) -> Vec3& { return s.fingers[f].normal; });
    add_vec(p + "god_object", [f](State& s) -> Vec3& { return s.fingers[f].god_object; });
    add(p + "viscous_force", [f](State& s) { s.fingers[f].viscous_force += 1.0; });
    add(p + "friction_mu", [f](State& s) { s.fingers[f].friction_mu += 1.0; });
    add(p + "friction_radius", [f](State& s) { s.fingers[f].friction_radius += 1.0; });
    add(p + "pitch_at_last_physics", [f](State& s) { s.fingers[f].pitch_at_last_physics += 1.0; });
    add(p + "has_pitch", [f](State& s) { s.fingers[f].has_pitch ^= true; });
    add_vec(p + "hip_at_last_physics", [f](State& s) -> Vec3& { return s.fingers[f].hip_at_last_physics; });
    add_vec(p + "window_force", [f](State& s) -> Vec3& { return s.fingers[f].window_force; });
    add(p + "has_last_physics", [f](State& s) { s.fingers[f].has_last_physics ^= true; });
  }
  add("fingers (one more)", [](State& s) { s.fingers.emplace_back(); });
  add("pairs[0].a", [](State& s) { ++s.pairs[0].a; });
  add("pairs[0].b", [](State& s) { ++s.pairs[0].b; });
  add("pairs[0].count", [](State& s) { --s.pairs[0].count; });
  for (int k = 0; k < kMaxPairPoints; ++k) {
    const std::string p = "pairs[0].points[" + std::to_string(k) + "].";
    add(p + "key", [k](State& s) { ++s.pairs[0].points[k].key; });
    add(p + "slipping", [k](State& s) { s.pairs[0].points[k].slipping ^= true; });
    add_vec(p + "anchor_a", [k](State& s) -> Vec3& { return s.pairs[0].points[k].anchor_a; });
    add_vec(p + "anchor_b", [k](State& s) -> Vec3& { return s.pairs[0].points[k].anchor_b; });
  }
  add("pairs (one more)", [](State& s) { s.pairs.emplace_back(); });
  return m;
}

}  // namespace

TEST_CASE("fnv1a64 matches the published FNV-1a 64 test vectors", "[state_hash]") {
  // Vectors from the FNV reference (Fowler, Noll, Vo; isthe.com/chongo/tech/comp/fnv).
  CHECK(fnv1a64("", 0) == 0xcbf29ce484222325ull);
  CHECK(fnv1a64("a", 1) == 0xaf63dc4c8601ec8cull);
  CHECK(fnv1a64("foobar", 6) == 0x85944171f73967e8ull);
  // Continuing from a hash is hashing the concatenation.
  CHECK(fnv1a64("bar", 3, fnv1a64("foo", 3)) == fnv1a64("foobar", 6));
}

TEST_CASE("equal states hash equal, a copy or a rebuild alike", "[state_hash]") {
  const State a = sample_state();
  const State b = a;
  const State c = sample_state();
  CHECK(state_hash(a) == state_hash(b));
  CHECK(state_hash(a) == state_hash(c));
  CHECK(state_hash(State{}) == state_hash(State{}));
  CHECK(state_hash(a) != state_hash(State{}));
}

// A pair's point slots past its count hold nothing of the state (the gather fills only the points
// it found): changing one changes no hash, so no run's hash depends on what an earlier contact left.
TEST_CASE("a pair's unused point slots are not in its hash", "[state_hash]") {
  State s = sample_state();
  s.pairs[0].count = 3;
  const std::uint64_t h0 = state_hash(s);
  s.pairs[0].points[3].anchor_a.x() += 1.0;
  s.pairs[0].points[kMaxPairPoints - 1].key += 1;
  CHECK(state_hash(s) == h0);
  s.pairs[0].points[2].key += 1;   // a point in use
  CHECK(state_hash(s) != h0);
}

TEST_CASE("changing any one field of the state changes its hash", "[state_hash]") {
  const State base = sample_state();
  const std::uint64_t h0 = state_hash(base);
  const auto all = mutations();
  // tick, 2 bodies x 64 scalars (54 + 8 of the BDF2 history + asleep, still_steps) (+ a floor point), the body count, 2 fingers x 27, the finger
  // count, the pair's bodies a and b and its point count, 16 points x 8, the pair count: every field is visited.
  REQUIRE(all.size() == 1 + 2 * 64 + 1 + 2 * 34 + 1 + 3 + 16 * 8 + 1);
  std::vector<std::uint64_t> seen{h0};
  for (const auto& [name, mutate] : all) {
    State s = base;
    mutate(s);
    const std::uint64_t h = state_hash(s);
    INFO(name);
    CHECK(h != h0);
    seen.push_back(h);
  }
  // And no two single-field changes collide (a swapped or skipped field order would).
  std::sort(seen.begin(), seen.end());
  CHECK(std::adjacent_find(seen.begin(), seen.end()) == seen.end());
}

TEST_CASE("the hash sees exact bits: -0.0 differs from 0.0, one ulp counts", "[state_hash]") {
  State a = sample_state();
  a.bodies[0].velocity.x() = 0.0;
  State b = a;
  b.bodies[0].velocity.x() = -0.0;   // == 0.0 as a number, different bits
  CHECK(state_hash(a) != state_hash(b));
  State c = sample_state();
  c.fingers[1].god_object.z() = std::nextafter(c.fingers[1].god_object.z(), 1e300);
  CHECK(state_hash(c) != state_hash(sample_state()));
}

TEST_CASE("swapping two bodies or two fingers changes the hash (order is part of the state)",
          "[state_hash]") {
  const State base = sample_state();
  State s = base;
  std::swap(s.bodies[0], s.bodies[1]);
  CHECK(state_hash(s) != state_hash(base));
  s = base;
  std::swap(s.fingers[0], s.fingers[1]);
  CHECK(state_hash(s) != state_hash(base));
}

// The hash's word step folds high bits down: negating two different doubles (two differences
// in a word's top bit only) changes the hash, as does negating one. With FNV-1a's xor and
// multiply alone on whole words, a top-bit difference never leaves the top bit and the two
// cancel (h' = h + 2^63 twice): this test fails without the xor-shift.
TEST_CASE("sign flips of two values do not cancel in the state hash", "[state_hash]") {
  State s;
  s.bodies.resize(1);
  s.bodies[0].position = Vec3(0.25, -1.5, 3.0);
  s.bodies[0].velocity = Vec3(0.5, 2.0, -0.125);
  const std::uint64_t h = state_hash(s);
  int cancelled = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      State t = s;
      t.bodies[0].position[i] = -t.bodies[0].position[i];
      t.bodies[0].velocity[j] = -t.bodies[0].velocity[j];
      cancelled += state_hash(t) == h;
      State u = s;
      u.bodies[0].position[i] = -u.bodies[0].position[i];
      u.bodies[0].position[(i + 1) % 3] = -u.bodies[0].position[(i + 1) % 3];
      cancelled += state_hash(u) == h;
    }
  }
  CHECK(cancelled == 0);
}
