// Lua off the real-time thread (README.md "Devices", scripting/README.md
// "Threads"). In a paced run every Lua trajectory is sampled ahead of the loop, on a script
// thread, into a bounded single-producer single-consumer ring per trajectory; the loop's thread
// only takes samples out (two atomics, no lock, no allocation). A ring that runs dry holds the
// last sample and counts it. A trajectory that reads the simulation view gets it one physics
// period later than an unpaced run gives it: the sample for servo tick k is computed with the
// view as it stood at the end of tick k - D - 1 (D servo ticks per physics period), so that the
// script thread has a whole physics period to compute the next one.
//
// Unpaced runs do not use any of this: they call Lua on the loop's thread in today's exact
// order, bit for bit.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "graspsim/hw/trajectory.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::app {

// One trajectory sample for one servo tick.
struct TickSample {
  std::int64_t tick = -1;          // servo tick the sample is for (its time: tick / rate_servo)
  hw::TrajectorySample sample;     // m and rad, world (as the Lua function returned them)
};

// A bounded single-producer single-consumer queue over a preallocated array: push on one thread,
// front/pop on another, never both ends on one. Lock-free (an acquire/release pair per item),
// never allocates after construction. Holds `capacity` items.
template <typename T>
class SpscRing {
 public:
  explicit SpscRing(std::size_t capacity) : slots_(capacity + 1) {}
  std::size_t capacity() const { return slots_.size() - 1; }
  // Producer: the slot the next push fills, or nullptr when full; commit() publishes it.
  T* back() {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (next(tail) == head_.load(std::memory_order_acquire)) return nullptr;
    return &slots_[tail];
  }
  void commit() { tail_.store(next(tail_.load(std::memory_order_relaxed)), std::memory_order_release); }
  bool push(const T& item) {
    T* slot = back();
    if (slot == nullptr) return false;
    *slot = item;
    commit();
    return true;
  }
  // Consumer: the oldest item, or nullptr when empty; pop() frees it.
  T* front() {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_.load(std::memory_order_acquire)) return nullptr;
    return &slots_[head];
  }
  void pop() { head_.store(next(head_.load(std::memory_order_relaxed)), std::memory_order_release); }
  // Every slot, for setting them up before either thread uses the ring.
  std::vector<T>& storage() { return slots_; }
  bool full() const {
    return next(tail_.load(std::memory_order_relaxed)) == head_.load(std::memory_order_acquire);
  }

 private:
  std::size_t next(std::size_t i) const { return i + 1 == slots_.size() ? 0 : i + 1; }
  std::vector<T> slots_;
  alignas(64) std::atomic<std::size_t> head_{0};   // next to read (consumer's)
  alignas(64) std::atomic<std::size_t> tail_{0};   // next to write (producer's)
};

class ScriptThread;

// What one Lua trajectory becomes in a paced run: its ring, the Lua trajectory itself (only the
// script thread calls it once started), and the consumer's state (only the loop's thread).
struct TrajectoryFeed {
  explicit TrajectoryFeed(std::size_t capacity) : ring(capacity) {}
  SpscRing<TickSample> ring;
  std::unique_ptr<hw::Trajectory> lua;   // the scenario's LuaTrajectory
  std::atomic<bool> abandoned{false};    // its consumer was destroyed: the script thread skips it
  // Consumer side (the loop's thread):
  TickSample last;                       // the sample last returned (tick -1: none yet)
  std::int64_t holds = 0;                // requests answered by holding `last`: the ring was dry
  std::int64_t off_grid = 0;             // requests at a time that is no servo tick (held too)
};

// The trajectory a device gets in a paced run: sample(t) takes the sample of servo tick
// k = t * rate_servo from the ring (within 1 ns of k / rate; a device sampling its hand at its
// own rate, e.g. sim-phantom at 1 kHz under a 3 kHz servo loop, asks at such instants). Before
// the script thread starts it calls the Lua trajectory directly (device set-up, not yet paced).
class PrefetchedTrajectory final : public hw::Trajectory {
 public:
  PrefetchedTrajectory(ScriptThread& owner, std::shared_ptr<TrajectoryFeed> feed);
  ~PrefetchedTrajectory() override;
  hw::TrajectorySample sample(double t) override;

 private:
  ScriptThread& owner_;
  std::shared_ptr<TrajectoryFeed> feed_;
};

struct ScriptThreadOptions {
  int rate_servo = 3000;             // Hz
  std::int64_t physics_divisor = 60; // D: servo ticks per physics period
  std::int64_t end_tick = 0;         // the run's servo ticks: samples are computed up to end_tick + capacity
  bool view = false;                 // some trajectory reads the view (Scenario::uses_view)
  // RunSeams::wait_for_script (a paced run on a fake clock, which outruns any thread): the loop
  // waits for a sample that the script thread can still compute instead of holding. Never with a
  // hand on a device: a slow script would then stall the loop.
  bool wait_for_samples = false;
};

// The look-ahead: servo ticks of samples each ring holds, at least two physics periods and at
// least 20 ms (kStallTimeout: a script thread descheduled for less than the loop's own stall
// timeout never starves it). 120 ticks (40 ms) at 3000 / 50 Hz.
std::size_t lookahead_ticks(int rate_servo, std::int64_t physics_divisor);

// Views queued between the loop and the script thread (a queue, not a latest-value slot: the
// sample for tick k needs the view of one exact tick).
inline constexpr std::size_t kViewSlots = 8;

// Gives every finger's `touching` room for the longest name it can take (an object's or
// "floor"), so that filling the snapshot again for the same model allocates nothing.
void presize_snapshot(scripting::Snapshot& s);

class ScriptThread {
 public:
  ScriptThread(const scripting::Scenario& scenario, const ScriptThreadOptions& options);
  ~ScriptThread();   // stops and joins
  ScriptThread(const ScriptThread&) = delete;
  ScriptThread& operator=(const ScriptThread&) = delete;

  // The Scenario::TrajectoryWrapper of a paced run: registers a feed for the Lua trajectory.
  // Only before start().
  std::unique_ptr<hw::Trajectory> wrap(std::unique_ptr<hw::Trajectory> lua);
  bool has_feeds() const { return !feeds_.empty(); }

  // Starts the script thread (from now on it alone uses the scenario's Lua state) and returns
  // once every ring holds its first look-ahead of samples, or the script failed. The view before
  // the first tick must already be written into Lua (Scenario::update_view) by the caller.
  void start();
  // Stops and joins the thread; afterwards the caller's thread may use Lua again. Idempotent.
  void stop();
  bool running() const { return running_; }

  // The loop's thread, after tick n's work: tick n is done (and its view, if any, was pushed).
  void tick_done(std::int64_t n) { progress_.store(n, std::memory_order_release); }
  // Before start(), with a view: every view slot becomes a copy of `prototype` (a snapshot of
  // this run's model) with room for any contact name, so that filling one allocates nothing.
  void prepare_views(const scripting::Snapshot& prototype);
  // The loop's thread, after a physics tick n: the slot to fill with the view (or nullptr when
  // the script thread is kViewSlots views behind: counted, that view skipped), then commit.
  scripting::Snapshot* view_slot();
  void commit_view(std::int64_t n);

  // Summary after stop(): counts over every feed.
  std::int64_t holds() const;
  std::int64_t off_grid() const;
  std::int64_t views_dropped() const { return views_dropped_; }
  std::size_t lookahead() const { return capacity_; }   // servo ticks
  // "N samples held (a ring ran dry), look-ahead L ticks (X ms)[, view one physics period later
  // (Y ms)]".
  std::string summary() const;

  // For PrefetchedTrajectory (the loop's thread).
  const ScriptThreadOptions& options() const { return options_; }
  // Whether the script thread failed computing tick <= k (then error() says why).
  bool failed_by(std::int64_t k) const;
  const std::string& error() const { return error_; }
  // Whether the script thread will still compute tick k without the loop going further.
  bool can_compute(std::int64_t k) const;

 private:
  struct ViewSlot {
    std::int64_t tick = -1;       // servo tick after which the view was taken
    scripting::Snapshot view;
  };
  void run();   // the script thread
  bool rings_have_room() const;

  const scripting::Scenario& scenario_;
  ScriptThreadOptions options_;
  std::size_t capacity_;
  std::vector<std::shared_ptr<TrajectoryFeed>> feeds_;
  SpscRing<ViewSlot> views_;
  std::int64_t views_dropped_ = 0;      // the loop's thread
  std::atomic<std::int64_t> progress_{-1};   // last servo tick the loop finished
  std::atomic<std::int64_t> produced_{0};    // servo ticks computed into every ring
  std::atomic<bool> stop_{false};
  std::atomic<bool> failed_{false};
  std::int64_t failed_tick_ = 0;   // written before failed_ (release), read after it (acquire)
  std::string error_;              // likewise
  bool running_ = false;
  std::thread thread_;
};

}  // namespace graspsim::app
