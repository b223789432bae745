// Force safety, in one place: every rule a force obeys on its way to a device.
//   0. Device::render clamps every force to the device's limits (clamp_force below), and
//      Device::release renders zero; the run loop releases every device when it stalls, falls
//      behind, fails or ends.
// Inside a backend with a motor model, ForceSafety then holds each force to the current limit:
//   1. clamped to the peak limit (clamp_force: NaN or infinite requests render zero),
//   2. derated by a thermal model so the continuous limit holds in the long run,
//   3. ramped in over a rise time after start (and after every stall or release): the one force
//      ramp, a limit that rises from 0 to P, so no force jumps on, and one below the ramping
//      limit is rendered whole (a hand's small corrections act from the start),
//   4. zero when no request came for `stall_timeout` of the device clock, and after release().
// It is driven by an injected time (s, the device's own clock); it never reads a clock.
//
// Laws (hw/README.md, "Force safety"):
//   ramp:     L_ramp(t) = P ramp_fraction(t - t_start, T_rise)   (the one ramp law, below)
//   thermal:  H, the exponentially time-averaged squared force, time constant tau:
//             H(t + dt) = H(t) + (1 - exp(-dt / tau)) (|F|^2 - H(t))  with F held over dt;
//             L_therm^2 = P^2 - (P^2 - C^2) H / C^2   (P when cold, C when H = C^2).
//             Saturated from cold, H(t) = C^2 (1 - exp(-t P^2 / (C^2 tau))): the limit falls from
//             P to C with time constant tau C^2 / P^2. H never exceeds C^2 as long as output()
//             is called at least every dt_max = -tau ln(1 - C^2 / P^2) (0.27 s for the Premium
//             1.5 at tau = 10 s; a device calls it every tick); past that, H can overshoot C^2 and
//             the limit is 0 until it cools back (safe, never above).
//   limit:    L(t) = min(L_ramp, L_therm), and 0 when stalled or released.
#pragma once

#include <Eigen/Core>

namespace graspsim::hw {

using Vec3 = Eigen::Vector3d;

struct DeviceLimits {
  double max_force = 10.0;   // N: largest force magnitude the device may render
};

// The largest force a device may be asked for is the limit, in the direction asked; NaN or
// infinite components render zero (a non-finite request is a fault, and the safe output for a
// fault is no force).
Vec3 clamp_force(const Vec3& force, const DeviceLimits& limits);

// The ramp law: the fraction of the peak the limit allows a time `elapsed` (s) after the ramp
// starts, r = min(1, elapsed / T_rise) for elapsed >= 0, 0 before, and 1 when T_rise = 0 (no ramp).
double ramp_fraction(double elapsed, double rise_time);

struct ForceSafetyConfig {
  double peak_force = 8.5;               // N: P, the largest force ever rendered
  double continuous_force = 1.4;         // N: C, the mean-square limit, C <= P
  double thermal_time_constant = 10.0;   // s: tau (estimate: a small DC motor's winding, 10-20 s)
  double rise_time = 1.0;                // s: T_rise of the linear ramp at start; 0 = no ramp
  double stall_timeout = 0.05;           // s: no request for this long renders zero
};

class ForceSafety {
 public:
  // Throws std::invalid_argument naming the field when a value is not finite or out of range
  // (P > 0, 0 < C <= P, tau > 0, T_rise >= 0, stall_timeout > 0).
  explicit ForceSafety(const ForceSafetyConfig& config);

  // A new request at device time `time` (s): clamped to the current limit and held until the
  // next one. The first request after construction, a stall or release() starts the ramp.
  // Returns the force as limited now.
  Vec3 request(const Vec3& force, double time);
  // The force to apply from `time` (s) on: integrates the thermal state over the interval since
  // the last call with the force applied in it, then returns the held request clamped to the
  // limit at `time` (zero when stalled, released, or `time` is not finite).
  Vec3 output(double time);
  // Zero from now until the next request, which ramps in again.
  void release();

  double limit(double time) const;                 // N: L(time), for the next output
  double heat() const { return heat_; }            // N^2: H
  bool active() const { return active_; }         // false before start, after a stall or release
  const ForceSafetyConfig& config() const { return config_; }

 private:
  double limit_now(double time) const;   // N: min(L_ramp, L_therm), ignoring stall

  ForceSafetyConfig config_;
  bool active_ = false;         // a request is held and the ramp has started
  double start_time_ = 0.0;     // s: t_start of the ramp
  double request_time_ = 0.0;   // s: time of the held request
  Vec3 request_{0.0, 0.0, 0.0}; // N: the held request, peak-clamped
  double heat_ = 0.0;           // N^2: H
  bool have_output_ = false;    // output() has been called once
  double output_time_ = 0.0;    // s: time of the last output()
  double output_sq_ = 0.0;      // N^2: |F|^2 of the last output, held since output_time_
};

}  // namespace graspsim::hw
