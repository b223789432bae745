// The live view's seam in the run loop (view/README.md, "Live"): after every tick that ran the
// haptic or physics loop, the loop copies what the page draws into a preallocated snapshot and
// publishes it; one reader thread (the view's server) takes the newest at its own rate. A triple
// buffer: three snapshots sized at start from the model, the writer owning one, the reader one,
// and the newest waiting in the third; publishing and taking are one atomic exchange each, so
// neither side locks, waits or allocates, and a snapshot is never read while it is written.
// The engine knows nothing of it.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "graspsim/engine/math.hpp"

namespace graspsim::app {

struct LiveBody {
  Vec3 position{0.0, 0.0, 0.0};        // m, world: centre of mass (the /physics row's)
  Quat orientation = Quat::Identity(); // 1: body to world
};

struct LiveFinger {
  Vec3 hip{0.0, 0.0, 0.0};             // m, world: this servo tick's
  Vec3 god_object{0.0, 0.0, 0.0};      // m, world: the last haptic tick's
  Vec3 force{0.0, 0.0, 0.0};           // N, world: force on the finger, the last haptic tick's
  Vec3 surface_point{0.0, 0.0, 0.0};   // m, world: the HIP on the contacted face (= HIP free)
  double friction_radius = 0.0;        // m: mu depth, the friction circle's radius
  std::int8_t state = 0;               // 0 free, 1 stick, 2 slip (the trace's /haptic state)
};

struct LiveSnapshot {
  std::int64_t tick = -1;          // servo tick it was taken after (-1: none yet)
  std::int64_t physics_tick = -1;  // servo tick of the physics step the bodies' poses are from
  std::int64_t haptic_tick = -1;   // servo tick of the haptic step the fingers' contact is from
  std::vector<LiveBody> bodies;    // Model::bodies order
  std::vector<LiveFinger> fingers; // Model::fingers order
};

class LiveChannel {
 public:
  // Three snapshots of `bodies` bodies and `fingers` fingers: the only allocation.
  LiveChannel(std::size_t bodies, std::size_t fingers);
  LiveChannel(const LiveChannel&) = delete;
  LiveChannel& operator=(const LiveChannel&) = delete;

  std::size_t bodies() const { return slots_[0].bodies.size(); }
  std::size_t fingers() const { return slots_[0].fingers.size(); }

  // Writer (one thread): fill every field of back(), then publish() makes it the newest.
  LiveSnapshot& back() { return slots_[back_]; }
  void publish();

  // Reader (one thread): the newest snapshot published since the last take(), or nullptr when
  // none is newer. The pointer stays valid, and unchanged by the writer, until the next take().
  const LiveSnapshot* take();

 private:
  static constexpr unsigned kIndex = 3u;   // bits of the waiting slot's index
  static constexpr unsigned kFresh = 4u;   // set: the waiting slot was published, not yet taken
  std::array<LiveSnapshot, 3> slots_;
  unsigned back_ = 0;                      // the writer's slot
  unsigned front_ = 1;                     // the reader's slot
  std::atomic<unsigned> middle_{2};        // the waiting slot | kFresh
};

}  // namespace graspsim::app
