// Force safety: peak clamp, thermal derating, ramp-in, stall and release (force_safety.hpp).
#include "graspsim/hw/force_safety.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace graspsim::hw {

Vec3 clamp_force(const Vec3& force, const DeviceLimits& limits) {
  const double limit = limits.max_force;
  if (!force.allFinite() || !(limit > 0.0)) return Vec3::Zero();   // a fault renders nothing
  if (std::isinf(limit)) return force;
  // Work on force / s with s its largest component: |u| lies in [1, sqrt 3], so no square
  // overflows (forces up to DBL_MAX) or underflows (limits down to the smallest doubles).
  const double s = force.cwiseAbs().maxCoeff();
  if (s == 0.0) return force;
  const Vec3 u = force / s;
  const double u_norm = u.norm();
  if (s <= limit / u_norm && force.norm() <= limit) return force;   // within: unchanged
  // Along the same direction, 4 ulp short of the limit, so that no way of computing the norm
  // (any summation order, with or without extended precision) finds it above the limit.
  constexpr double kShrink = 1.0 - 4.0 * std::numeric_limits<double>::epsilon();
  return u * (limit / u_norm * kShrink);
}

double ramp_fraction(double elapsed, double rise_time) {
  return rise_time > 0.0 ? std::clamp(elapsed / rise_time, 0.0, 1.0) : 1.0;
}

namespace {
void require(bool ok, const char* field, double value, const char* rule) {
  if (!ok)
    throw std::invalid_argument(std::string("force safety: ") + field + " = " +
                                std::to_string(value) + " must be " + rule);
}
}  // namespace

ForceSafety::ForceSafety(const ForceSafetyConfig& c) : config_(c) {
  require(std::isfinite(c.peak_force) && c.peak_force > 0.0, "peak_force", c.peak_force,
          "finite and > 0 (N)");
  require(std::isfinite(c.continuous_force) && c.continuous_force > 0.0 &&
              c.continuous_force <= c.peak_force,
          "continuous_force", c.continuous_force, "finite, > 0 and <= peak_force (N)");
  require(std::isfinite(c.thermal_time_constant) && c.thermal_time_constant > 0.0,
          "thermal_time_constant", c.thermal_time_constant, "finite and > 0 (s)");
  require(std::isfinite(c.rise_time) && c.rise_time >= 0.0, "rise_time", c.rise_time,
          "finite and >= 0 (s)");
  require(std::isfinite(c.stall_timeout) && c.stall_timeout > 0.0, "stall_timeout",
          c.stall_timeout, "finite and > 0 (s)");
}

double ForceSafety::limit_now(double time) const {
  const double p = config_.peak_force;
  const double c = config_.continuous_force;
  const double ramp = p * ramp_fraction(time - start_time_, config_.rise_time);
  const double therm_sq = std::max(0.0, p * p - (p * p - c * c) * (heat_ / (c * c)));
  return std::min(ramp, std::sqrt(therm_sq));
}

double ForceSafety::limit(double time) const {
  if (!active_ || !std::isfinite(time) || time - request_time_ > config_.stall_timeout) return 0.0;
  return limit_now(time);
}

Vec3 ForceSafety::request(const Vec3& force, double time) {
  if (!std::isfinite(time)) {   // no clock, no force
    release();
    return Vec3::Zero();
  }
  if (!active_ || time - request_time_ > config_.stall_timeout) {
    active_ = true;   // first request, or the first after a stall or release: ramp in again
    start_time_ = time;
  }
  request_ = clamp_force(force, DeviceLimits{config_.peak_force});
  request_time_ = time;
  return clamp_force(request_, DeviceLimits{limit_now(time)});
}

Vec3 ForceSafety::output(double time) {
  if (!std::isfinite(time)) return Vec3::Zero();
  if (have_output_ && time > output_time_) {
    // Exact for a force held over [output_time_, time]: H relaxes to |F|^2 with time constant tau.
    const double a = -std::expm1(-(time - output_time_) / config_.thermal_time_constant);
    heat_ += a * (output_sq_ - heat_);
  }
  if (!have_output_ || time > output_time_) output_time_ = time;   // a clock going back holds H
  have_output_ = true;
  if (active_ && time - request_time_ > config_.stall_timeout) active_ = false;   // stalled
  const Vec3 f = active_ ? clamp_force(request_, DeviceLimits{limit_now(time)}) : Vec3::Zero();
  output_sq_ = f.squaredNorm();
  return f;
}

void ForceSafety::release() {
  active_ = false;
  request_ = Vec3::Zero();
}

}  // namespace graspsim::hw
