// The simulation: a Model, its State, and the fixed order of work inside one servo tick.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "graspsim/engine/collision.hpp"
#include "graspsim/engine/grasp_rules.hpp"
#include "graspsim/engine/implicit_step.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/object_contact.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

class Simulation {
 public:
  // Validates the model (std::invalid_argument naming the field) and starts from its initial state.
  explicit Simulation(Model model);

  // One servo tick, in this order (the only place the order is written):
  //   1 servo    the HIP of every finger from `input`
  //   2 haptic   (tick % (servo/haptic) == 0) friction cone for every finger, in finger order
  //   3 servo    force on every finger, k (GO - HIP) with the newest HIP; its reaction, acting at
  //              the contact point on the surface (GO less the pad radius), is added to the
  //              contacted body's physics window
  //   4 physics  (tick % (servo/physics) == 0), over dt = 1/physics s, by Model::integrator:
  //              paper     body-body contact wrenches for every pair in contact, all at the state
  //                        of this tick; then for every body, in body order: record the state at
  //                        this tick; residual F = finger impulse over the window / dt + floor +
  //                        other bodies + m g and T likewise; grasp rules, dead band; integrate
  //              implicit  every contact point (fingers, floor, body pairs) as a spring-damper
  //                        about this tick's state; each island of touching bodies solved at once
  //                        for its velocities at the end of the step; then for every body, in
  //                        body order: record; the solved change as F and T; grasp rules, dead
  //                        band; move (backward Euler, exact turn)
  //              then per body: clear the window; flag a body whose state diverged (record.hpp)
  //   5 tick += 1
  // Time is tick / servo, computed, never accumulated.
  // Inline: at 50 Hz, 59 of 60 ticks run no loop but the servo's, and in a scene without fingers
  // they run nothing at all, so a call would be a third of such a tick's cost.
  void step(const Input& input, TickRecord& record) {
    // The loops that run this tick, in locals: the stages write through `record`, so its fields
    // would be read back after every call.
    const bool haptic = to_haptic_ == 0;     // tick % (servo / haptic) == 0
    const bool physics = to_physics_ == 0;   // tick % (servo / physics) == 0
    record.tick = state_.tick;
    record.haptic_ran = haptic;
    record.physics_ran = physics;
    record.diverged_body = -1;
    if (!model_.fingers.empty()) {                  // the haptic and servo loops serve fingers only
      if (haptic) haptic_stage(input, record);      // 2: the friction cone, finger by finger
      servo_stage(input, record);                   // 3: finger forces, reactions into the window
    }
    if (physics) physics_stage(input, record);      // 4: move the bodies
    ++state_.tick;                                             // 5
    to_haptic_ = (haptic ? divisors_.haptic : to_haptic_) - 1;
    to_physics_ = (physics ? divisors_.physics : to_physics_) - 1;
  }

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  const Divisors& divisors() const { return divisors_; }
  // Whether the physics stage lists its contact points in TickRecord::contacts (off: the list
  // stays empty, and the step skips the copies, 2 to 3 % of a resting box's step). Off by
  // default; the run loop turns it on when a trace records /contacts. Changes no result.
  void record_contacts(bool on) { record_contacts_ = on; }
  bool records_contacts() const { return record_contacts_; }
  std::int64_t tick() const { return state_.tick; }
  double time() const { return static_cast<double>(state_.tick) / model_.rates.servo; }   // s

 private:
  // The stages of step(), in order.
  void haptic_stage(const Input& input, TickRecord& record);
  void servo_stage(const Input& input, TickRecord& record);
  void physics_stage(const Input& input, TickRecord& record);
  // The physics stage's parts.
  double gimbal_pitch_change(const Input& input);
  void wake_touched_bodies();
  void paper_contacts(TickRecord& record);
  void paper_body_step(int b, double pitch_change, TickRecord& record);
  void implicit_contacts(const Input& input);
  void implicit_solve(double pitch_change);
  void record_implicit_contacts(TickRecord& record) const;
  void implicit_body_step(int b, TickRecord& record);
  void record_sleeping(int b, TickRecord& record);
  BodyRecord& record_state(int b, int floor_contacts, TickRecord& record);
  void apply_grasp_rules(int b, double pitch_change, const Wrench& contact, BodyState& bs, Vec3& torque,
                         BodyRecord& rec);
  void mark_stepped(BodyState& bs) const;
  void finish_body_step(int b, TickRecord& record);

  Model model_;
  bool record_contacts_ = false;
  Divisors divisors_;
  State state_;
  // Servo ticks until the haptic and the physics loops next run (0: at this tick): the clock's
  // remainders by the divisors, kept by counting. (Two 64-bit divisions a tick cost an idle servo
  // tick as much as the rest of its work.) Only step() moves the clock, so they cannot drift.
  std::int64_t to_haptic_ = 0, to_physics_ = 0;
  std::shared_ptr<detail::FclWorld> fcl_;   // the bodies' FCL objects, one world for both below
  CollisionWorld collision_;
  bool collision_stale_ = false;   // bodies moved since collision_ was last updated
  std::vector<int> scratch_;   // candidate bodies of a finger query
  BodyContacts body_contacts_;            // body-body contact (its own broadphase)
  std::vector<Wrench> contact_wrench_;    // per body: the contact wrench the grasp rules see (paper:
                                          //   body-body, the floor's added per body; implicit: floor
                                          //   and bodies at the start of the step, pushing only)
  std::vector<int> contact_points_;       // per body: body-body contact points of this step
  std::vector<double> floor_reach_;       // m, per body: farthest floor point from the centre of mass
  std::vector<ContactPair> floor_pairs_;  // per body, with a floor: its pair with the floor (constant)
  std::vector<std::uint8_t> floor_clear_;  // per body: 1 when none of its floor points is active
  // The implicit step's buffers (sized once).
  ImplicitStep implicit_;
  StepHistory history_;                   // per body: what the BDF2 step needs of the last step
  std::vector<Coupling> couplings_;       // this step's contact points
  std::vector<std::uint8_t> awake_;       // per body: 1 when stepped
  std::vector<Vec3> v0_, w0_;             // m/s, rad/s, per body: velocities at the start of the step
                                          //   (w0 after the gyroscopic change)
  std::vector<Vec3> external_force_;      // N, per body: fingers' window mean and gravity
  std::vector<Vec3> external_torque_;     // N m, per body: fingers' window mean
  std::vector<int> floor_points_;         // per body: floor points pushing at the end of the step
  std::vector<Vec3> finger_point_;        // m, world, per finger: contact point of this servo tick
  std::vector<Vec3> finger_force_;        // N, world, per finger: force on the finger this servo tick
  std::vector<AxisRule> rules_;           // per body: its grasp rule this step
  std::vector<std::uint8_t> axis_active_; // per body: 1 when a rule holds its rate about an axis
  std::vector<Vec3> axis_;                // 1, world, per body: that axis
  std::vector<Vec3> axis_point_;          // m, world, per body: a point of it (the first god-object)
  std::vector<double> axis_rate_;         // rad/s, per body: the rate about it at the end of the step
};

}  // namespace graspsim
