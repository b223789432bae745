// The tick: devices, finger contact, forces, physics, in one fixed order.
#include "graspsim/engine/simulation.hpp"

#include <algorithm>
#include <cmath>

#include "graspsim/engine/finger_contact.hpp"
#include "graspsim/engine/local_model.hpp"
#include "fcl_world.hpp"

namespace graspsim {

namespace {
Model validated(Model model) {
  validate(model);
  return model;
}
}  // namespace

Simulation::Simulation(Model model)
    : model_(validated(std::move(model))),
      divisors_(graspsim::divisors(model_.rates)),
      state_(initial_state(model_)),
      fcl_(std::make_shared<detail::FclWorld>(model_)),
      collision_(model_, fcl_),
      finger_point_(model_.fingers.size()),
      contacts_(model_, fcl_),
      paper_(model_),
      implicit_(model_) {
  collision_.update(model_, state_);
  to_haptic_ = (divisors_.haptic - state_.tick % divisors_.haptic) % divisors_.haptic;
  to_physics_ = (divisors_.physics - state_.tick % divisors_.physics) % divisors_.physics;
  scratch_.reserve(model_.bodies.size());
}

void Simulation::haptic_stage(const Input& input, TickRecord& record) {
  // The finger broadphase is only asked by free fingers (a finger in contact tracks its own
  // body's surface): it follows the bodies here, when one will ask, not at every physics step.
  // Same poses, same answers (the candidates are sorted), so this changes no result. Under the
  // local model the bodies move at every tick, so it follows them at every haptic tick.
  if (collision_stale_ || uses_local_model(model_)) {
    for (const FingerState& fs : state_.fingers) {
      if (fs.phase == ContactPhase::kFree) {
        collision_.update(model_, state_);
        collision_stale_ = false;
        break;
      }
    }
  }
  for (std::size_t f = 0; f < model_.fingers.size(); ++f) {
    finger_haptic_step(model_, state_, collision_, static_cast<int>(f), input.fingers[f].hip,
                       state_.fingers[f], record.haptic[f], scratch_);
  }
}

void Simulation::servo_stage(const Input& input, TickRecord& record) {
  // Force on each finger from the newest HIP; the reaction acts on the body at the GO.
  for (std::size_t f = 0; f < model_.fingers.size(); ++f) {
    const Vec3& hip = input.fingers[f].hip;
    Vec3 contact_point;
    const Vec3 force = finger_force(model_, state_, static_cast<int>(f), hip, contact_point);
    record.servo[f].hip = hip;
    record.servo[f].force = force;
    if (record.haptic_ran) record.haptic[f].force = force;   // the haptic row shows the same force
    state_.fingers[f].hip_at_last_servo = hip;
    finger_point_[f] = contact_point;
    const int b = state_.fingers[f].body;
    if (b >= 0) {
      BodyState& bs = state_.bodies[b];
      bs.window_force -= force;
      // About the centre as the fast loops see it (local_model.hpp; the physics pose without it).
      const Vec3 centre = uses_local_model(model_) ? fast_loop_pose(model_, bs, state_.tick).position : bs.position;
      bs.window_torque += (contact_point - centre).cross(-force);
      if (model_.integrator == Integrator::kImplicit) state_.fingers[f].window_force -= force;
    }
  }
}

void Simulation::physics_stage(const Input& input, TickRecord& record) {
  const double pitch_change = gimbal_pitch_change(input);
  wake_touched_bodies();
  record.contacts.clear();
  if (model_.integrator == Integrator::kPaper) {
    paper_.step(model_, state_, contacts_, divisors_.physics, pitch_change, record_contacts_, record);
  } else {
    implicit_.step(model_, state_, contacts_, input, finger_point_, divisors_.physics, pitch_change, record_contacts_,
                   record);
  }
  collision_stale_ = true;
}

double Simulation::gimbal_pitch_change(const Input& input) {
  // The gimbal finger's pitch change since the last physics step (section 3.2, solution 1).
  double pitch_change = 0.0;
  if (const int g = model_.grasp.gimbal_finger; g >= 0) {
    FingerState& fs = state_.fingers[g];
    const double pitch = input.fingers[g].gimbal.y();
    if (fs.has_pitch) pitch_change = pitch - fs.pitch_at_last_physics;
    fs.pitch_at_last_physics = pitch;
    fs.has_pitch = true;
  }
  return pitch_change;
}

void Simulation::wake_touched_bodies() {
  // Sleep: a finger on a sleeping body (holding it now, or pushed it since the last step)
  // wakes it before anything is computed; the contact gather wakes one a moving body reaches.
  if (!model_.sleep.enabled) return;
  for (const FingerState& fs : state_.fingers) {
    if (fs.body >= 0) wake(state_.bodies[fs.body]);
  }
  for (BodyState& bs : state_.bodies) {
    if (bs.asleep && (!bs.window_force.isZero(0.0) || !bs.window_torque.isZero(0.0))) wake(bs);
  }
}

}  // namespace graspsim
