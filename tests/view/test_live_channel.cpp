// The live view's triple buffer (app/live_channel.hpp): one writer publishing as fast as it can,
// one reader thread taking as fast as it can. Every field of a snapshot the writer fills is a
// function of one counter k, so a snapshot read while it is written (torn) has fields from two
// values of k and is caught; the reader also sees k only increase (the newest, never an older one
// after a newer). Run under -fsanitize=thread too (view/README.md, "Live").
#include <catch2/catch.hpp>

#include <atomic>
#include <thread>

#include "app/live_channel.hpp"
#include "tests/support/count_allocations.hpp"   // this executable only: it replaces operator new

namespace {

using graspsim::app::LiveChannel;
using graspsim::app::LiveSnapshot;

// Every field from k: doubles k + an offset per field (exact below 2^53), the state k mod 3.
void fill(LiveSnapshot& s, std::int64_t k) {
  s.tick = k;
  s.physics_tick = k + 1;
  s.haptic_tick = k + 2;
  double x = static_cast<double>(k);
  for (auto& b : s.bodies) {
    b.position = {x + 1, x + 2, x + 3};
    b.orientation.coeffs() << x + 4, x + 5, x + 6, x + 7;
  }
  for (auto& f : s.fingers) {
    f.hip = {x + 8, x + 9, x + 10};
    f.god_object = {x + 11, x + 12, x + 13};
    f.force = {x + 14, x + 15, x + 16};
    f.surface_point = {x + 17, x + 18, x + 19};
    f.friction_radius = x + 20;
    f.state = static_cast<std::int8_t>(k % 3);
  }
}

// Fields that disagree with the snapshot's own tick (0: whole).
int torn_fields(const LiveSnapshot& s) {
  const std::int64_t k = s.tick;
  const double x = static_cast<double>(k);
  int bad = (s.physics_tick != k + 1) + (s.haptic_tick != k + 2);
  for (const auto& b : s.bodies) {
    bad += b.position != graspsim::Vec3(x + 1, x + 2, x + 3);
    bad += b.orientation.coeffs() != Eigen::Vector4d(x + 4, x + 5, x + 6, x + 7);
  }
  for (const auto& f : s.fingers) {
    bad += f.hip != graspsim::Vec3(x + 8, x + 9, x + 10);
    bad += f.god_object != graspsim::Vec3(x + 11, x + 12, x + 13);
    bad += f.force != graspsim::Vec3(x + 14, x + 15, x + 16);
    bad += f.surface_point != graspsim::Vec3(x + 17, x + 18, x + 19);
    bad += f.friction_radius != x + 20;
    bad += f.state != static_cast<std::int8_t>(k % 3);
  }
  return bad;
}

}  // namespace

TEST_CASE("live channel: nothing to take before a publish, then the newest, once") {
  LiveChannel c(1, 2);
  CHECK(c.take() == nullptr);   // the reader's slot holds no published snapshot
  fill(c.back(), 5);
  c.publish();
  fill(c.back(), 6);
  c.publish();   // 6 replaces 5 in the waiting slot: the reader skips 5
  const LiveSnapshot* s = c.take();
  REQUIRE(s != nullptr);
  CHECK(s->tick == 6);
  CHECK(torn_fields(*s) == 0);
  CHECK(c.take() == nullptr);   // nothing newer than 6
  CHECK(c.bodies() == 1);
  CHECK(c.fingers() == 2);
}

TEST_CASE("live channel: a reader thread under a writer's stress loop never sees a torn or older snapshot") {
  // 5 bodies and 3 fingers: a snapshot of 5 * 7 + 3 * 13 doubles, long enough that a copy racing
  // the writer would mix two values of k. 200000 publishes: about 0.05 s here, longer under TSan.
  LiveChannel c(5, 3);
  constexpr std::int64_t kPublishes = 200000;
  std::atomic<bool> done{false};
  std::int64_t taken = 0, torn = 0, backwards = 0, last = -1;
  std::thread reader([&] {
    for (;;) {
      const bool finished = done.load(std::memory_order_acquire);
      if (const LiveSnapshot* s = c.take()) {
        ++taken;
        torn += torn_fields(*s) != 0;
        backwards += s->tick <= last;
        last = s->tick;
      } else if (finished) {
        return;
      }
    }
  });
  for (std::int64_t k = 0; k < kPublishes; ++k) {
    fill(c.back(), k);
    c.publish();
  }
  done.store(true, std::memory_order_release);
  reader.join();
  INFO("snapshots taken: " << taken);
  CHECK(torn == 0);
  CHECK(backwards == 0);
  CHECK(last == kPublishes - 1);   // the last publish is always taken: the newest is never lost
  CHECK(taken > 1);                // the reader ran beside the writer, not only after it
}

TEST_CASE("live channel: filling, publishing and taking allocate nothing (the paced loop's rule)") {
  // The snapshots are sized once, at construction; after that the writer assigns into them and
  // the two sides swap indices. 1000 rounds, each counted by the replaced operator new.
  LiveChannel c(4, 3);
  const long before = graspsim::test::allocations();
  std::int64_t taken = 0;
  for (std::int64_t k = 0; k < 1000; ++k) {
    fill(c.back(), k);
    c.publish();
    if (const LiveSnapshot* s = c.take()) taken += s->tick == k;
  }
  const long allocated = graspsim::test::allocations() - before;
  CHECK(allocated == 0);
  CHECK(taken == 1000);   // each round's publish was the newest when taken
}
