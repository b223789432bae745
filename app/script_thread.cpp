// Lua on a script thread in paced runs (script_thread.hpp).
#include "app/script_thread.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "app/pacer.hpp"

namespace graspsim::app {
namespace {
// How long the script thread sleeps when it may not compute the next tick yet (its rings are full
// or, with a view, the loop has not finished the tick it needs): a fraction of a 3 kHz period.
constexpr auto kIdle = std::chrono::microseconds(20);
}  // namespace

std::size_t lookahead_ticks(int rate_servo, std::int64_t physics_divisor) {
  const auto stall = static_cast<std::int64_t>(std::ceil(kStallTimeout * rate_servo));
  return static_cast<std::size_t>(std::max<std::int64_t>({2 * physics_divisor, stall, 1}));
}

void presize_snapshot(scripting::Snapshot& s) {
  std::size_t longest = 5;   // "floor"
  for (const scripting::ObjectSnapshot& o : s.objects) longest = std::max(longest, o.name.size());
  for (scripting::FingerSnapshot& f : s.fingers) f.touching.reserve(longest);
}

PrefetchedTrajectory::PrefetchedTrajectory(ScriptThread& owner, std::shared_ptr<TrajectoryFeed> feed)
    : owner_(owner), feed_(std::move(feed)) {}

PrefetchedTrajectory::~PrefetchedTrajectory() { feed_->abandoned.store(true, std::memory_order_relaxed); }

hw::TrajectorySample PrefetchedTrajectory::sample(double t) {
  // Before the script thread runs (device set-up) this thread may call Lua itself.
  if (!owner_.running()) return feed_->lua->sample(t);
  TrajectoryFeed& f = *feed_;
  const double rate = owner_.options().rate_servo;
  const double x = t * rate;
  std::int64_t k = std::isfinite(x) && x > -0.5 ? static_cast<std::int64_t>(std::llround(x)) : -1;
  // Servo tick k's instant, computed as the loop computes it (Simulation::time); 1 ns absorbs
  // another rounding of the same instant (a device clock's j / 1000 for k = 3 j at 3 kHz).
  if (k < 0 || !(std::fabs(t - static_cast<double>(k) / rate) <= 1e-9)) {
    // No servo tick at t: the script's sample of the tick before it (a zero-order hold of the
    // servo-rate script), counted. Without it the first such request would return the zero
    // sample nobody computed (a sim-phantom at 1 kHz under a 1500 Hz loop: the hand at the
    // origin).
    ++f.off_grid;
    if (k < 0) return f.last.sample;
    k = static_cast<std::int64_t>(std::floor(x));
  }
  if (k <= f.last.tick) return f.last.sample;   // this tick again, or one gone from the ring
  for (;;) {
    TickSample* s = f.ring.front();
    if (s == nullptr) {
      if (owner_.failed_by(k)) throw scripting::ScenarioError(owner_.error());
      if (owner_.options().wait_for_samples && owner_.can_compute(k)) {
        std::this_thread::yield();
        continue;
      }
      ++f.holds;   // dry: the script thread is behind; hold the last sample
      return f.last.sample;
    }
    if (s->tick < k) {   // a tick this device did not ask for (it samples at its own rate)
      f.ring.pop();
      continue;
    }
    if (s->tick == k) {
      f.last = *s;
      f.ring.pop();
      return f.last.sample;
    }
    ++f.holds;   // s->tick > k: cannot happen (every tick is computed in order); hold
    return f.last.sample;
  }
}

ScriptThread::ScriptThread(const scripting::Scenario& scenario, const ScriptThreadOptions& options)
    : scenario_(scenario),
      options_(options),
      capacity_(lookahead_ticks(options.rate_servo, options.physics_divisor)),
      views_(kViewSlots) {}

ScriptThread::~ScriptThread() { stop(); }

std::unique_ptr<hw::Trajectory> ScriptThread::wrap(std::unique_ptr<hw::Trajectory> lua) {
  auto feed = std::make_shared<TrajectoryFeed>(capacity_);
  feed->lua = std::move(lua);
  feeds_.push_back(feed);
  return std::make_unique<PrefetchedTrajectory>(*this, std::move(feed));
}

void ScriptThread::prepare_views(const scripting::Snapshot& prototype) {
  for (ViewSlot& slot : views_.storage()) {
    slot.view = prototype;
    presize_snapshot(slot.view);
  }
}

bool ScriptThread::rings_have_room() const {
  for (const auto& f : feeds_)
    if (!f->abandoned.load(std::memory_order_relaxed) && f->ring.full()) return false;
  return true;
}

bool ScriptThread::failed_by(std::int64_t k) const {
  return failed_.load(std::memory_order_acquire) && failed_tick_ <= k;
}

bool ScriptThread::can_compute(std::int64_t k) const {
  if (stop_.load(std::memory_order_relaxed) || failed_.load(std::memory_order_acquire)) return false;
  if (k >= options_.end_tick + static_cast<std::int64_t>(capacity_)) return false;
  return !options_.view || k <= progress_.load(std::memory_order_acquire) + options_.physics_divisor + 1;
}

void ScriptThread::start() {
  if (running_) return;
  // A trajectory made and dropped during set-up (sim-phantom's workspace probe) gets no samples.
  feeds_.erase(std::remove_if(feeds_.begin(), feeds_.end(),
                              [](const auto& f) { return f->abandoned.load(std::memory_order_relaxed); }),
               feeds_.end());
  running_ = true;
  thread_ = std::thread([this] { run(); });
  // The first look-ahead before the loop starts (this thread is not real-time yet): tick 0 is
  // never missing for want of a head start.
  const std::int64_t first = std::min<std::int64_t>(
      options_.end_tick + static_cast<std::int64_t>(capacity_),
      options_.view ? options_.physics_divisor + 1 : static_cast<std::int64_t>(capacity_));
  while (produced_.load(std::memory_order_acquire) < first && !failed_.load(std::memory_order_acquire))
    std::this_thread::sleep_for(kIdle);
}

void ScriptThread::stop() {
  if (!running_) return;
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  running_ = false;
}

scripting::Snapshot* ScriptThread::view_slot() {
  ViewSlot* slot = views_.back();
  if (slot == nullptr) {
    ++views_dropped_;
    return nullptr;
  }
  return &slot->view;
}

void ScriptThread::commit_view(std::int64_t n) {
  views_.back()->tick = n;
  views_.commit();
}

void ScriptThread::run() {
  const std::int64_t d = options_.physics_divisor;
  const std::int64_t last = options_.end_tick + static_cast<std::int64_t>(capacity_);
  std::int64_t k = 0;
  try {
    while (!stop_.load(std::memory_order_acquire)) {
      // Tick k may be computed when every ring has room and, with a view, when the loop has
      // finished tick k - D - 1, whose view the sample is computed with.
      bool ready = k < last && rings_have_room();
      if (ready && options_.view) ready = k - d - 1 <= progress_.load(std::memory_order_acquire);
      if (!ready) {
        std::this_thread::sleep_for(kIdle);
        continue;
      }
      if (options_.view) {
        // The views of every physics tick up to k - D - 1, in order: the last one is the one an
        // unpaced run's tick k - D saw.
        while (ViewSlot* v = views_.front()) {
          if (v->tick > k - d - 1) break;
          scenario_.update_view(v->view);
          views_.pop();
        }
      }
      const double t = static_cast<double>(k) / options_.rate_servo;   // as Simulation::time()
      for (const auto& f : feeds_) {
        if (f->abandoned.load(std::memory_order_relaxed)) continue;
        TickSample* slot = f->ring.back();   // room checked above; only this thread pushes
        slot->tick = k;
        slot->sample = f->lua->sample(t);
        f->ring.commit();
      }
      produced_.store(++k, std::memory_order_release);
    }
  } catch (const std::exception& e) {
    // The loop stops at tick k, when a ring runs dry there (PrefetchedTrajectory::sample).
    failed_tick_ = k;
    error_ = e.what();
    failed_.store(true, std::memory_order_release);
  }
}

std::int64_t ScriptThread::holds() const {
  std::int64_t n = 0;
  for (const auto& f : feeds_) n += f->holds;
  return n;
}

std::int64_t ScriptThread::off_grid() const {
  std::int64_t n = 0;
  for (const auto& f : feeds_) n += f->off_grid;
  return n;
}

std::string ScriptThread::summary() const {
  char buf[320];
  const double period = 1e3 / options_.rate_servo;   // ms
  int len = std::snprintf(buf, sizeof buf, "Lua on a script thread: %lld samples held (a ring ran dry), look-ahead %zu ticks (%.1f ms)",
                          static_cast<long long>(holds()), capacity_, static_cast<double>(capacity_) * period);
  if (options_.view && len > 0 && static_cast<std::size_t>(len) < sizeof buf)
    len += std::snprintf(buf + len, sizeof buf - len, ", view one physics period later than unpaced (%.1f ms)",
                         static_cast<double>(options_.physics_divisor) * period);
  if (views_dropped_ > 0 && len > 0 && static_cast<std::size_t>(len) < sizeof buf)
    len += std::snprintf(buf + len, sizeof buf - len, ", %lld views skipped", static_cast<long long>(views_dropped_));
  if (off_grid() > 0 && len > 0 && static_cast<std::size_t>(len) < sizeof buf)
    std::snprintf(buf + len, sizeof buf - len, ", %lld requests off the servo ticks held", static_cast<long long>(off_grid()));
  return buf;
}

}  // namespace graspsim::app
