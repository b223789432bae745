// The simulation: a Model, its State, and the fixed order of work inside one servo tick.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "graspsim/engine/collision.hpp"
#include "graspsim/engine/contact_gather.hpp"
#include "graspsim/engine/implicit_stage.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/paper_stage.hpp"
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
  //              one gather of every contact point (contact_gather.hpp), then
  //              paper     each point's force clamped, all at the state of this tick; then for
  //                        every body, in body order: record the state at this tick; residual
  //                        F = finger impulse over the window / dt + floor + other bodies + m g
  //                        and T likewise; grasp rules, dead band; integrate (paper_stage.hpp)
  //              implicit  every point (fingers too) a spring-damper about this tick's state;
  //                        the islands of bodies that push on each other solved at once for
  //                        their velocities at the end of the step; then for every body, in
  //                        body order: record; the solved change as F and T; grasp rules, dead
  //                        band; move (backward Euler or BDF2, exact turn) (implicit_stage.hpp)
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
  // The contact points of the last physics step, as gathered (paper) or solved (implicit).
  const std::vector<Coupling>& contact_points() const {
    return model_.integrator == Integrator::kPaper ? paper_.couplings() : implicit_.couplings();
  }
  // The gather the physics stage uses, for read-only queries at the state now (the stability
  // check's), so that a run has one FCL world.
  ContactGather& contacts() { return contacts_; }
  double time() const { return static_cast<double>(state_.tick) / model_.rates.servo; }   // s

 private:
  // The stages of step(), in order.
  void haptic_stage(const Input& input, TickRecord& record);
  void servo_stage(const Input& input, TickRecord& record);
  void physics_stage(const Input& input, TickRecord& record);
  // The physics stage's parts.
  double gimbal_pitch_change(const Input& input);
  void wake_touched_bodies();

  Model model_;
  bool record_contacts_ = false;
  Divisors divisors_;
  State state_;
  // Servo ticks until the haptic and the physics loops next run (0: at this tick): the clock's
  // remainders by the divisors, kept by counting. (Two 64-bit divisions a tick cost an idle servo
  // tick as much as the rest of its work.) Only step() moves the clock, so they cannot drift.
  std::int64_t to_haptic_ = 0, to_physics_ = 0;
  std::shared_ptr<detail::FclWorld> fcl_;   // the bodies' FCL objects, one world for the fingers and the bodies
  CollisionWorld collision_;
  bool collision_stale_ = false;   // bodies moved since collision_ was last updated
  std::vector<int> scratch_;       // candidate bodies of a finger query
  std::vector<Vec3> finger_point_; // m, world, per finger: contact point of this servo tick
  ContactGather contacts_;         // every contact point of the bodies, once a physics step
  PaperStage paper_;               // the integrators, each with what only it needs
  ImplicitStage implicit_;
};

}  // namespace graspsim
