// The simulated Phantom, `sim-phantom`: a stylus tip (point mass with viscous damping and Coulomb
// backdrive friction, per the device model table) held by a scripted hand: a spring-damper (the
// hand's impedance) pulling it toward the finger's trajectory, whose rest point the person
// slowly moves until the tip is where they intend (a voluntary correction, integral action on
// the position error, bounded). The device runs at its own rate with zero-order
// hold of the rendered force across its ticks, quantises its position to encoder counts and
// stops at the workspace limits; the rendered force goes through ForceSafety. Deterministic:
// no clock, the state advances only in read(). hw/README.md, "Simulated Phantom", has the laws.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>

#include "graspsim/hw/device.hpp"
#include "graspsim/hw/device_models.hpp"
#include "graspsim/hw/force_safety.hpp"
#include "graspsim/hw/trajectory.hpp"

namespace graspsim::hw {

struct SimPhantomConfig {
  std::string model = "premium-1.5";   // a device_models() key or name
  double device_rate_hz = 1000.0;      // Hz: device ticks (1000 like OpenHaptics, 3000 like the paper)
  // The hand: fingertip impedance after Hajian & Howe 1997 (index fingertip, roughly 100-800 N/m
  // and 1-4 N s/m depending on grip force); mid-range values.
  double hand_stiffness = 300.0;       // N/m: k_h, spring from the stylus to the trajectory
  double hand_damping = 2.0;           // N s/m: b_h, on the velocity relative to the trajectory
  // The voluntary correction: the hand's rest point is x_h + u with du/dt = (x_h - x) / tau_c,
  // so in steady state the tip is at the trajectory whatever force it meets (hw/README.md,
  // "Simulated Phantom"). tau_c: ESTIMATE, a few hundred ms, slower than a visually guided
  // correction's latency (about 0.2 s); +inf = no correction (the pure impedance hand).
  double hand_correction_time = 0.3;   // s: tau_c, > m / (b + b_h) for stability (Routh)
  // Anti-windup: the correction never makes the hand push harder than this, k_h |u| <= F_h
  // (against a wall, a workspace stop or a device at its force limit). ESTIMATE: above the
  // 1-10 N of precision grips (Westling & Johansson 1984, from memory), well under a maximal pinch.
  double hand_max_force = 20.0;        // N: F_h
  // Stylus integration steps per device tick (>= 1). Semi-implicit Euler's position leads by
  // half a step, which shortens the ZOH's effective delay from T/2 to (T - h)/2 and moves the
  // sampled-wall stability bound from 2b/T to 2b/(T - h): 50 keeps that bias at 2 %.
  int substeps = 50;
  Vec3 workspace_center{0.0, 0.0, 0.0};   // m: centre of the workspace box and encoder zero, in
                                          // the hand trajectory's frame
  double damping = std::numeric_limits<double>::quiet_NaN();   // N s/m: b; NaN = the model's
  double friction = std::numeric_limits<double>::quiet_NaN();  // N: mu; NaN = the model's
  // m: one encoder count; NaN = the model's, 0 = no quantisation (for tests of the linear law)
  double encoder_resolution = std::numeric_limits<double>::quiet_NaN();
  double rise_time = 1.0;              // s: force ramp-in (ForceSafetyConfig::rise_time)
  double stall_timeout = 0.05;         // s: zero force after this long without a render
  double thermal_time_constant = 10.0; // s: tau of the thermal derating (estimate)
};

class SimPhantom final : public Device {
 public:
  // Throws std::invalid_argument naming the field for an unknown model, a non-positive or
  // non-finite rate, stiffness, damping or substeps, or a null hand.
  SimPhantom(const SimPhantomConfig& config, std::unique_ptr<Trajectory> hand);

  // Advances the device through every device tick up to `time` (s) and returns the encoder
  // reading of the last one (held between device ticks). `tick` is not used. Throws
  // std::invalid_argument when `time` is not finite.
  DeviceSample read(std::int64_t tick, double time) override;
  DeviceLimits limits() const override { return DeviceLimits{model_.peak_force}; }
  std::string describe() const override;
  // Its box (the encoder never reads outside it), widened by one count for the rounding of
  // centre + count x resolution.
  Workspace workspace() const override;

  const DeviceModel& model() const { return model_; }
  const ForceSafety& safety() const { return safety_; }
  std::int64_t device_tick() const { return device_tick_; }   // device ticks done
  const Vec3& tip_position() const { return x_; }    // m: true tip position (not quantised)
  const Vec3& tip_velocity() const { return v_; }    // m/s: tip velocity
  const Vec3& motor_force() const { return motor_; } // N: force the motors applied in the last device tick
  const Vec3& hand_offset() const { return u_; }     // m: u, the correction of the hand's rest point
  Vec3 hand_force() const;   // N: the hand spring's force on the tip now, k_h (x_h + u - x) (no damper)
  const Vec3& workspace_min() const { return lo_; }  // m: the workspace box's lower corner (hand frame)
  const Vec3& workspace_max() const { return hi_; }  // m: its upper corner
  double damping() const { return b_; }              // N s/m: b in use
  double friction() const { return mu_; }             // N: mu in use

 protected:
  void output(const Vec3& force) override;
  // After Device::release() has sent the zero force: the force limit ramps in again from zero
  // at the next render (ForceSafety::release), as after a stall.
  void on_release() override { safety_.release(); }

 private:
  void step();                   // one device tick
  Vec3 encoder() const;          // m: quantised, inside the workspace

  SimPhantomConfig config_;
  const DeviceModel& model_;
  std::unique_ptr<Trajectory> hand_;
  ForceSafety safety_;
  double period_;                // s: T = 1 / device_rate_hz
  double b_;                     // N s/m: device viscous damping
  double mu_;                    // N: Coulomb backdrive friction
  double res_;                   // m: encoder count, 0 = none
  Vec3 lo_, hi_;                 // m: workspace box corners
  Vec3 count_lo_{0.0, 0.0, 0.0}, count_hi_{0.0, 0.0, 0.0};   // encoder counts (integers stored as double) at the box corners
  std::int64_t device_tick_ = 0;
  double clock_ = 0.0;           // s: time of the last read, stamps render requests
  Vec3 x_{0.0, 0.0, 0.0};        // m
  Vec3 v_{0.0, 0.0, 0.0};        // m/s
  Vec3 motor_{0.0, 0.0, 0.0};    // N
  Vec3 u_{0.0, 0.0, 0.0};        // m: the hand's correction (its rest point is x_h + u)
  double u_max_ = 0.0;           // m: F_h / k_h, the bound on |u| (inf when k_h = 0)
  double correction_rate_ = 0.0; // 1/s: 1 / tau_c (0 = none)
  TrajectorySample hand_now_;    // the hand at the current device tick
  DeviceSample sample_;          // the reading at the current device tick
};

// The `sim-phantom` backend's factory.
std::unique_ptr<Device> make_sim_phantom(const SimPhantomConfig& config,
                                         std::unique_ptr<Trajectory> hand);

}  // namespace graspsim::hw
