// The simulated Phantom (sim_phantom.hpp).
//
// Per device tick n -> n+1 (period T = 1 / rate), with the motor force F_m = ForceSafety::output(t_n)
// held over the tick (zero-order hold) and the hand target moving linearly from x_h(t_n) to
// x_h(t_{n+1}) (velocity v_h), the tip is integrated with N = substeps steps of h = T / N:
//   F      = k_h (x_h + u - x) + b_h (v_h - v) + F_m              (explicit)
//   u      = u + h (x_h - x) / tau_c, then |u| <= F_h / k_h       (the hand's voluntary
//            correction, explicit, clamped: anti-windup)
//   v'     = (v + h F / m) / (1 + h b / m)                         (viscous damping implicit)
//   v''    = 0 if |v'| <= h mu / m, else v' (1 - (h mu / m) / |v'|)   (Coulomb, stick when the
//            friction impulse can stop the tip within the step: no chatter)
//   x      = x + h v''                                             (semi-implicit Euler)
//   end stops: a coordinate past the workspace box is put back on it and its outward velocity
//   zeroed (an inelastic mechanical stop).
// The reading at t_{n+1} is the tip quantised to encoder counts from the workspace centre.
#include "graspsim/hw/sim_phantom.hpp"

#include <cmath>
#include <stdexcept>

namespace graspsim::hw {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("sim-phantom: " + what);
}

ForceSafetyConfig safety_config(const SimPhantomConfig& c, const DeviceModel& m) {
  ForceSafetyConfig s;
  s.peak_force = m.peak_force;
  s.continuous_force = m.continuous_force;
  s.thermal_time_constant = c.thermal_time_constant;
  s.rise_time = c.rise_time;
  s.stall_timeout = c.stall_timeout;
  return s;
}

const DeviceModel& checked_model(const SimPhantomConfig& c) {
  try {
    return device_model(c.model);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("sim-phantom: model: ") + e.what());
  }
}

}  // namespace

SimPhantom::SimPhantom(const SimPhantomConfig& config, std::unique_ptr<Trajectory> hand)
    : config_(config),
      model_(checked_model(config)),
      hand_(std::move(hand)),
      safety_(safety_config(config, model_)),
      period_(1.0 / config.device_rate_hz),
      b_(std::isnan(config.damping) ? model_.damping : config.damping),
      mu_(std::isnan(config.friction) ? model_.backdrive_friction : config.friction),
      res_(std::isnan(config.encoder_resolution) ? model_.encoder_resolution
                                                 : config.encoder_resolution) {
  require(hand_ != nullptr, "hand: a trajectory is required");
  require(std::isfinite(config.device_rate_hz) && config.device_rate_hz > 0.0,
          "device_rate_hz must be finite and > 0 (Hz), got " + std::to_string(config.device_rate_hz));
  require(std::isfinite(config.hand_stiffness) && config.hand_stiffness >= 0.0,
          "hand_stiffness must be finite and >= 0 (N/m), got " + std::to_string(config.hand_stiffness));
  require(std::isfinite(config.hand_damping) && config.hand_damping >= 0.0,
          "hand_damping must be finite and >= 0 (N s/m), got " + std::to_string(config.hand_damping));
  require(std::isfinite(b_) && b_ >= 0.0, "damping must be finite and >= 0 (N s/m), got " + std::to_string(b_));
  require(std::isfinite(mu_) && mu_ >= 0.0, "friction must be finite and >= 0 (N), got " + std::to_string(mu_));
  require(std::isfinite(res_) && res_ >= 0.0,
          "encoder_resolution must be finite and >= 0 (m), got " + std::to_string(res_));
  require(config.substeps >= 1 && config.substeps <= 1000,
          "substeps must be in [1, 1000], got " + std::to_string(config.substeps));
  require(config.workspace_center.allFinite(), "workspace_center must be finite (m)");
  require(!std::isnan(config.hand_correction_time) && config.hand_correction_time > 0.0,
          "hand_correction_time must be > 0 (s; inf = no correction), got " +
              std::to_string(config.hand_correction_time));
  require(std::isfinite(config.hand_max_force) && config.hand_max_force > 0.0,
          "hand_max_force must be finite and > 0 (N), got " + std::to_string(config.hand_max_force));
  // The hand-stylus loop m x'' = -k_h (x - u) - (b + b_h) x', u' = -x / tau_c has the
  // characteristic polynomial m tau s^3 + (b + b_h) tau s^2 + k_h tau s + k_h: Routh-stable iff
  // (b + b_h) tau_c > m.
  require(config.hand_stiffness == 0.0 || std::isinf(config.hand_correction_time) ||
              (b_ + config.hand_damping) * config.hand_correction_time > model_.tip_mass,
          "hand_correction_time must exceed m / (b + b_h) = " +
              std::to_string(model_.tip_mass / (b_ + config.hand_damping)) +
              " s (the hand's correction would be unstable), got " +
              std::to_string(config.hand_correction_time));
  correction_rate_ = std::isinf(config.hand_correction_time) || config.hand_stiffness == 0.0
                         ? 0.0
                         : 1.0 / config.hand_correction_time;
  u_max_ = config.hand_max_force / config.hand_stiffness;   // inf when k_h = 0 (u unused then)
  // Explicit hand spring: stable for h sqrt(k_h / m) < 2; ask for a wide margin.
  const double h = period_ / config.substeps;
  require(h * std::sqrt(config.hand_stiffness / model_.tip_mass) < 0.5,
          "hand_stiffness too stiff for the integration step: raise substeps or the device rate");
  const Vec3 half = 0.5 * model_.workspace;
  lo_ = config.workspace_center - half;
  hi_ = config.workspace_center + half;
  if (res_ > 0.0)
    for (int i = 0; i < 3; ++i) {
      count_lo_[i] = std::ceil(-half[i] / res_);
      count_hi_[i] = std::floor(half[i] / res_);
    }
  hand_now_ = hand_->sample(0.0);
  x_ = hand_now_.position.cwiseMax(lo_).cwiseMin(hi_);
  sample_.position = encoder();
  sample_.gimbal = hand_now_.gimbal;
}

std::string SimPhantom::describe() const {
  return std::string("sim-phantom (") + model_.name + ", " +
         std::to_string(static_cast<long long>(std::llround(config_.device_rate_hz))) + " Hz)";
}

Workspace SimPhantom::workspace() const {
  const double margin = res_ > 0.0 ? res_ : 1e-9;   // m
  return Workspace{lo_ - Vec3::Constant(margin), hi_ + Vec3::Constant(margin)};
}

Vec3 SimPhantom::hand_force() const {
  return config_.hand_stiffness * (hand_now_.position + u_ - x_);
}

Vec3 SimPhantom::encoder() const {
  if (res_ == 0.0) return x_;   // unquantised; x_ is inside the box already
  Vec3 p;
  for (int i = 0; i < 3; ++i) {
    double q = std::nearbyint((x_[i] - config_.workspace_center[i]) / res_);
    q = std::fmin(std::fmax(q, count_lo_[i]), count_hi_[i]);
    p[i] = config_.workspace_center[i] + q * res_;
  }
  return p;
}

void SimPhantom::step() {
  const double t0 = static_cast<double>(device_tick_) * period_;
  const double t1 = static_cast<double>(device_tick_ + 1) * period_;
  motor_ = safety_.output(t0);
  const TrajectorySample hand1 = hand_->sample(t1);
  const Vec3 xh0 = hand_now_.position;
  const Vec3 vh = (hand1.position - xh0) / period_;
  const int n = config_.substeps;
  const double h = period_ / n;
  const double m = model_.tip_mass;
  const double stop = h * mu_ / m;   // m/s: friction's speed change per step
  for (int s = 0; s < n; ++s) {
    const Vec3 xh = xh0 + vh * (h * s);
    const Vec3 f = config_.hand_stiffness * (xh + u_ - x_) + config_.hand_damping * (vh - v_) + motor_;
    if (correction_rate_ > 0.0) {
      u_ += (h * correction_rate_) * (xh - x_);
      const double un = u_.norm();
      if (un > u_max_) u_ *= u_max_ / un;   // anti-windup: the hand pushes at most F_h
    }
    Vec3 v = (v_ + (h / m) * f) / (1.0 + h * b_ / m);
    const double speed = v.norm();
    v = speed <= stop ? Vec3::Zero() : Vec3(v * (1.0 - stop / speed));
    x_ += h * v;
    for (int i = 0; i < 3; ++i) {
      if (x_[i] < lo_[i]) { x_[i] = lo_[i]; v[i] = std::fmax(v[i], 0.0); }
      if (x_[i] > hi_[i]) { x_[i] = hi_[i]; v[i] = std::fmin(v[i], 0.0); }
    }
    v_ = v;
  }
  hand_now_ = hand1;
  ++device_tick_;
  sample_.position = encoder();
  sample_.gimbal = hand_now_.gimbal;
}

DeviceSample SimPhantom::read(std::int64_t /*tick*/, double time) {
  if (!std::isfinite(time))
    throw std::invalid_argument("sim-phantom: read at a non-finite time");
  // Device ticks due by `time`; the 1e-6 absorbs the rounding of time = k / rate.
  const double due = std::floor(time * config_.device_rate_hz + 1e-6);
  while (static_cast<double>(device_tick_) < due) step();
  clock_ = time;
  return sample_;
}

void SimPhantom::output(const Vec3& force) { safety_.request(force, clock_); }

std::unique_ptr<Device> make_sim_phantom(const SimPhantomConfig& config,
                                         std::unique_ptr<Trajectory> hand) {
  return std::make_unique<SimPhantom>(config, std::move(hand));
}

}  // namespace graspsim::hw
