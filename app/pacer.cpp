// The real-time pacer: absolute deadlines on CLOCK_MONOTONIC, overrun and stall accounting.
#include "app/pacer.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <pthread.h>
#include <sched.h>
#include <stdexcept>

namespace graspsim::app {

std::int64_t SteadyClock::now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

void SteadyClock::sleep_until_ns(std::int64_t deadline) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline / 1000000000);
  ts.tv_nsec = static_cast<long>(deadline % 1000000000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

Pacer::Pacer(MonotonicClock& clock, int rate, double stall_timeout, double lag_limit)
    : clock_(clock), rate_(rate) {
  if (rate <= 0) throw std::invalid_argument("pacer: the servo rate must be > 0 Hz (got " + std::to_string(rate) + ")");
  if (!(stall_timeout > 0.0 && stall_timeout < 1e6)) throw std::invalid_argument("pacer: the stall timeout must be > 0 s");
  if (!(lag_limit > 0.0 && lag_limit < 1e6)) throw std::invalid_argument("pacer: the lag limit must be > 0 s");
  stall_ns_ = static_cast<std::int64_t>(std::llround(stall_timeout * 1e9));
  lag_ns_ = static_cast<std::int64_t>(std::llround(lag_limit * 1e9));
}

void Pacer::start() {
  start_ns_ = last_end_ns_ = clock_.now_ns();
  overruns_ = ticks_ = 0;
  worst_ = worst_gap_ = 0.0;
}

TickPace Pacer::end_tick(std::int64_t n) {
  TickPace pace;
  // floor((n + 1) 1e9 / rate) ns, exact in integers: no rounding of the period accumulates
  // (3 kHz has no whole-ns period); int64 holds it for 9e9 ticks (35 days at 3 kHz).
  const std::int64_t deadline = start_ns_ + (n + 1) * 1000000000 / rate_;
  const std::int64_t now = clock_.now_ns();
  ++ticks_;
  pace.gap = static_cast<double>(now - last_end_ns_) * 1e-9;
  pace.stalled = now - last_end_ns_ > stall_ns_;
  if (pace.gap > worst_gap_) worst_gap_ = pace.gap;
  if (now > deadline) {
    pace.overrun = true;
    pace.lateness = static_cast<double>(now - deadline) * 1e-9;
    pace.lagging = now - deadline > lag_ns_;
    ++overruns_;
    if (pace.lateness > worst_) worst_ = pace.lateness;
    last_end_ns_ = now;
  } else {
    clock_.sleep_until_ns(deadline);
    last_end_ns_ = deadline;   // the next tick's work starts at the deadline, not when we woke
  }
  return pace;
}

std::string Pacer::summary() const {
  char buf[160];
  std::snprintf(buf, sizeof buf,
                "%lld of %lld ticks overran their deadline (worst %.3f ms late), longest gap between "
                "ticks %.3f ms",
                static_cast<long long>(overruns_), static_cast<long long>(ticks_), worst_ * 1e3,
                worst_gap_ * 1e3);
  return buf;
}

namespace {
// Middle of the SCHED_FIFO range: above ordinary threads and most daemons, below the kernel's
// own threaded IRQ handlers (priority 50) so that the device's interrupts still run.
constexpr int kRealtimePriority = 40;
}  // namespace

std::string enter_realtime() {
  sched_param p{};
  p.sched_priority = kRealtimePriority;
  const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
  if (err == 0) return "";
  return std::string("cannot run the servo loop as SCHED_FIFO priority ") + std::to_string(kRealtimePriority) + ": " +
         std::strerror(err) + " (needs CAP_SYS_NICE or an rtprio limit, e.g. ulimit -r 40); pacing with normal priority";
}

void leave_realtime() {
  sched_param p{};
  p.sched_priority = 0;
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &p);
}

std::string probe_realtime() {
  int policy = 0;
  sched_param before{};
  pthread_getschedparam(pthread_self(), &policy, &before);
  const std::string why = enter_realtime();
  if (why.empty()) pthread_setschedparam(pthread_self(), policy, &before);
  return why;
}

}  // namespace graspsim::app
