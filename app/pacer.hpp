// Real-time pacing of the lockstep loop (README.md, "Devices"): with a real device attached, servo
// tick n must finish by start + (n + 1) / rate on a monotonic clock. The pacer sleeps until that
// deadline, counts the ticks that miss it (overruns), and reports a stall (a tick whose forces
// went out more than `stall_timeout` after the previous tick's) so that the run loop releases
// every device. The clock is injected: tests drive a fake one (no wall-clock thresholds), runs
// use SteadyClock.
#pragma once

#include <cstdint>
#include <string>

namespace graspsim::app {

// The stall timeout of graspsim run (s): longer than a scheduling hiccup of a kernel without
// PREEMPT_RT (a few ms), well under the ~100 ms a hand needs to react, so nobody feels a stale
// force for longer than that before every device is released.
inline constexpr double kStallTimeout = 0.02;

// The lag limit of graspsim run (s): a loop that falls this far behind its schedule releases
// every device too, even if no single gap was a stall. A loop steadily slower than its rate
// refreshes forces in time but runs at a longer period than the contact was tuned for (the
// sampled-wall bound 2 b / T uses the real T), and its simulated time lags the hand: 100 ms is
// a hand's reaction time, and far more than the scheduling hiccups a loop at full rate makes up
// (a few ms on a shared VM).
inline constexpr double kLagLimit = 0.1;

class MonotonicClock {
 public:
  virtual ~MonotonicClock() = default;
  virtual std::int64_t now_ns() = 0;                     // ns, monotonic, arbitrary origin
  virtual void sleep_until_ns(std::int64_t deadline) = 0;   // returns at or after `deadline`
};

// CLOCK_MONOTONIC, absolute clock_nanosleep (no drift from summed relative sleeps).
class SteadyClock final : public MonotonicClock {
 public:
  std::int64_t now_ns() override;
  void sleep_until_ns(std::int64_t deadline) override;
};

struct TickPace {
  bool overrun = false;        // the tick's work ended after its deadline
  bool stalled = false;        // its forces followed the previous tick's by more than the timeout
  bool lagging = false;        // it ended more than the lag limit past its deadline
  double lateness = 0.0;       // s: how far past the deadline (0 when on time)
  double gap = 0.0;            // s: since the previous tick ended (tick 0: since start())
};

class Pacer {
 public:
  // rate: servo ticks per second (> 0); stall_timeout (s, > 0): the longest a device may hold
  // one force, i.e. the gap between two ticks' ends that counts as a stall.
  //
  // Two limits, either of which releases every device: a stall (the gap between two ticks'
  // ends past `stall_timeout`: a device holding a stale force) and a lag (a tick ending more than
  // `lag_limit` past its deadline: a loop steadily too slow for its rate). Lateness is not held
  // to the 20 ms stall timeout: on a shared VM hiccups of a few ms, each made up, add up past it,
  // and would stop runs whose longest gap is a few ms.
  Pacer(MonotonicClock& clock, int rate, double stall_timeout, double lag_limit = kLagLimit);
  void start();                        // tick 0's period begins now
  // After tick n's work: returns how it kept its deadline start + (n + 1) / rate, and sleeps
  // until that deadline when early. Deadlines stay on the absolute schedule (a late tick is made
  // up by the following ones when they are quicker), so simulated time keeps pace with the
  // hand's time instead of drifting behind it after every overrun.
  TickPace end_tick(std::int64_t n);
  std::int64_t overruns() const { return overruns_; }
  std::int64_t ticks() const { return ticks_; }
  double worst_lateness() const { return worst_; }   // s
  double worst_gap() const { return worst_gap_; }    // s: the longest gap between two ticks' ends
  double stall_timeout() const { return static_cast<double>(stall_ns_) * 1e-9; }   // s
  double lag_limit() const { return static_cast<double>(lag_ns_) * 1e-9; }         // s
  std::string summary() const;   // "N of M ticks overran (worst X ms late), longest gap Y ms"

 private:
  MonotonicClock& clock_;
  std::int64_t rate_;        // Hz
  std::int64_t start_ns_ = 0;
  std::int64_t stall_ns_;    // ns
  std::int64_t lag_ns_;      // ns
  std::int64_t last_end_ns_ = 0;   // ns: when the previous tick ended (its forces were out)
  std::int64_t overruns_ = 0, ticks_ = 0;
  double worst_ = 0.0;       // s
  double worst_gap_ = 0.0;   // s
};

// Real-time scheduling of the calling thread (SCHED_FIFO at a middle priority), where the system
// allows it. Returns "" on success, else a one-line reason (for the warning); leave_realtime
// returns the thread to SCHED_OTHER.
std::string enter_realtime();
void leave_realtime();
// Whether enter_realtime() would succeed, without staying real-time ("" yes, else why not).
std::string probe_realtime();

}  // namespace graspsim::app
