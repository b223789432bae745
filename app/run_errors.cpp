// Messages for the ways a run stops (run_errors.hpp).
#include "app/run_errors.hpp"

#include <cstdio>
#include <cstring>
#include <sstream>

namespace graspsim::app {

std::string energy_gain_message(const Model& model, const EnergyGain& g, double t, std::int64_t tick) {
  std::ostringstream msg;
  msg << "objects[" << g.body + 1 << "] '" << model.bodies[g.body].name << "'";
  if (g.bodies > 1) msg << " and the " << g.bodies - 1 << " bodies touching it";
  msg << " gained " << g.energy - g.reference << " J with no finger on " << (g.bodies > 1 ? "them" : "it") << ", from " << g.reference
      << " J at t = " << g.since << " s to " << g.energy << " J at t = " << t << " s (tick " << tick
      << "; allowed " << g.bound << " J): the integration is unstable";
  if (model.integrator == Integrator::kPaper) {
    msg << " (the paper's explicit step at rates.physics = " << model.rates.physics
        << " Hz; raise the rate, soften the contact, or use integrator = \"implicit\")";
  }
  return msg.str();
}

std::string divergence_message(const Model& model, const State& state, int body, double t, std::int64_t tick) {
  const BodyState& bs = state.bodies[body];
  std::ostringstream msg;
  msg << "objects[" << body + 1 << "] '" << model.bodies[body].name << "' diverged at t = " << t << " s (tick "
      << tick << "): speed " << bs.velocity.norm() << " m/s, spin " << bs.angular_velocity.norm()
      << " rad/s (limits " << kDivergedSpeed << " m/s, " << kDivergedAngularSpeed
      << " rad/s); the explicit integration is unstable for these stiffnesses, dampings and "
         "masses at rates.physics = " << model.rates.physics << " Hz";
  return msg.str();
}

std::string pacing_message(const TickPace& pace, const Pacer& pacer, std::int64_t tick, int rate_servo) {
  char why[240];
  if (pace.stalled) {
    std::snprintf(why, sizeof why,
                  "the servo loop stalled: tick %lld's forces went out %.3f ms after the previous "
                  "tick's (stall timeout %.3f ms); every device was released",
                  static_cast<long long>(tick), pace.gap * 1e3, pacer.stall_timeout() * 1e3);
  } else {
    std::snprintf(why, sizeof why,
                  "the servo loop fell behind: tick %lld ended %.3f ms past its deadline (lag limit "
                  "%.3f ms): it cannot keep %lld Hz here; every device was released",
                  static_cast<long long>(tick), pace.lateness * 1e3, pacer.lag_limit() * 1e3,
                  static_cast<long long>(rate_servo));
  }
  return why;
}

std::string interrupted_message(int signal, double t) {
  const char* name = signal > 0 ? sigabbrev_np(signal) : nullptr;
  return std::string("interrupted") + (name ? std::string(" by SIG") + name : std::string()) + " at t = " +
         std::to_string(t) + " s";
}

}  // namespace graspsim::app
