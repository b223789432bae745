// The tick: devices, finger contact, forces, physics, in one fixed order.
#include "graspsim/engine/simulation.hpp"

#include <algorithm>
#include <cmath>

#include "graspsim/engine/finger_contact.hpp"
#include "graspsim/engine/grasp_rules.hpp"
#include "graspsim/engine/integrate.hpp"
#include "graspsim/engine/local_model.hpp"
#include "fcl_world.hpp"

namespace graspsim {

namespace {
Model validated(Model model) {
  validate(model);
  return model;
}

// Whether any finger is in contact with body b.
bool held_by_finger(const State& state, int b) {
  for (const FingerState& fs : state.fingers) {
    if (fs.body == b) return true;
  }
  return false;
}
}  // namespace

Simulation::Simulation(Model model)
    : model_(validated(std::move(model))),
      divisors_(graspsim::divisors(model_.rates)),
      state_(initial_state(model_)),
      fcl_(std::make_shared<detail::FclWorld>(model_)),
      collision_(model_, fcl_),
      body_contacts_(model_, fcl_),
      contact_wrench_(model_.bodies.size()),
      contact_points_(model_.bodies.size(), 0),
      implicit_(model_) {
  collision_.update(model_, state_);
  to_haptic_ = (divisors_.haptic - state_.tick % divisors_.haptic) % divisors_.haptic;
  to_physics_ = (divisors_.physics - state_.tick % divisors_.physics) % divisors_.physics;
  scratch_.reserve(model_.bodies.size());
  // How far below its centre of mass a body can reach the floor, with 1e-9 to spare.
  std::size_t floor_points = 0;
  for (const BodyParams& bp : model_.bodies) {
    floor_reach_.push_back(floor_reach(bp.shape) * (1.0 + 1e-9) + 1e-12);
    if (model_.floor.enabled) floor_pairs_.push_back(floor_pair(model_, static_cast<int>(floor_pairs_.size())));
    floor_points += static_cast<std::size_t>(floor_point_count(bp.shape));
  }
  floor_clear_.assign(model_.bodies.size(), 0);
  const std::size_t n = model_.bodies.size();
  couplings_.reserve(floor_points + model_.fingers.size() + kMaxPairPoints * n * (n > 0 ? n - 1 : 0) / 2);
  implicit_.reserve(couplings_.capacity());
  awake_.resize(n);
  floor_points_.resize(n);
  rules_.resize(n);
  axis_active_.resize(n);
  axis_.resize(n);
  axis_point_.resize(n);
  axis_rate_.resize(n);
  v0_.resize(n);
  w0_.resize(n);
  external_force_.resize(n);
  external_torque_.resize(n);
  history_.order = model_.implicit_order;
  history_.valid.resize(n);
  history_.signature.resize(n);
  history_.steps.resize(n);
  finger_point_.resize(model_.fingers.size());
  finger_force_.resize(model_.fingers.size());
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
    finger_force_[f] = force;
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
    paper_contacts(record);
    for (std::size_t b = 0; b < model_.bodies.size(); ++b) paper_body_step(static_cast<int>(b), pitch_change, record);
  } else {
    implicit_contacts(input);
    implicit_solve(pitch_change);
    if (record_contacts_) record_implicit_contacts(record);
    for (std::size_t b = 0; b < model_.bodies.size(); ++b) implicit_body_step(static_cast<int>(b), record);
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
  // wakes it before anything is computed; BodyContacts wakes one a moving body reaches.
  if (!model_.sleep.enabled) return;
  for (const FingerState& fs : state_.fingers) {
    if (fs.body >= 0) wake(state_.bodies[fs.body]);
  }
  for (BodyState& bs : state_.bodies) {
    if (bs.asleep && (!bs.window_force.isZero(0.0) || !bs.window_torque.isZero(0.0))) wake(bs);
  }
}

void Simulation::paper_contacts(TickRecord& record) {
  // Body against body first, every pair at the state of this tick (equal and opposite).
  std::fill(contact_wrench_.begin(), contact_wrench_.end(), Wrench{});
  std::fill(contact_points_.begin(), contact_points_.end(), 0);
  body_contacts_.step(model_, state_, contact_wrench_, contact_points_, record_contacts_ ? &record.contacts : nullptr);
}

// The paper's step of one body (section 3.1): the residual force and torque at the state of this
// tick (fingers' window, floor points, other bodies, gravity), the grasp rules and the dead band,
// then the explicit integration.
void Simulation::paper_body_step(int b, double pitch_change, TickRecord& record) {
  const BodyParams& bp = model_.bodies[b];
  BodyState& bs = state_.bodies[b];
  if (bs.asleep) {
    record_sleeping(b, record);
    return;
  }
  // Impulse-consistent: the step spans servo/physics ticks, and each servo tick's force acts
  // for one servo period, so the body gets sum(f) / servo = mean(f) * dt. (Dividing by the
  // ticks actually accumulated would apply tick 0's force for a whole step.)
  const double per_tick = 1.0 / static_cast<double>(divisors_.physics);
  Wrench floor;
  int floor_contacts = 0;
  if (model_.floor.enabled) {
    if (bs.position.z() - floor_reach_[b] > model_.floor.height) {
      // No floor point can reach the floor: what floor_contact would give (nothing, every
      // point inactive), without visiting the points (2,562 on the profile's mesh).
      if (!floor_clear_[b]) {
        for (VertexContact& vc : bs.floor_contacts) vc.active = false;
        floor_clear_[b] = 1;
      }
    } else {
      floor_contacts = floor_contact(model_, b, bs, floor, record_contacts_ ? &record.contacts : nullptr);
      floor_clear_[b] = floor_contacts == 0 ? 1 : 0;
    }
  }
  floor.force += contact_wrench_[b].force;   // from here on: every object contact
  floor.torque += contact_wrench_[b].torque;
  const Vec3 force = bs.window_force * per_tick + floor.force + bp.mass * model_.gravity;
  Vec3 torque = bs.window_torque * per_tick + floor.torque;

  BodyRecord& rec = record_state(b, floor_contacts, record);
  apply_grasp_rules(b, pitch_change, floor, bs, torque, rec);
  dead_band(model_.grasp.dead_band, torque);
  rec.force = force;
  rec.torque = torque;
  const double dt = 1.0 / model_.rates.physics;
  mark_stepped(bs);
  integrate_body(bp, model_.gyroscopic, bs, force, torque, dt);
  finish_body_step(b, record);
}

void Simulation::record_sleeping(int b, TickRecord& record) {
  // Nothing to do: its pose stays as it is, bit for bit.
  const BodyState& bs = state_.bodies[b];
  BodyRecord& rec = record.physics[b];
  rec = BodyRecord{};
  rec.position = bs.position;
  rec.orientation = quat_of(bs.rotation);
  int touching = 0;
  for (const VertexContact& vc : bs.floor_contacts) touching += vc.active ? 1 : 0;
  rec.floor_contacts = touching;
  rec.body_contacts = contact_points_[b];
}

BodyRecord& Simulation::record_state(int b, int floor_contacts, TickRecord& record) {
  const BodyState& bs = state_.bodies[b];
  BodyRecord& rec = record.physics[b];
  rec.position = bs.position;
  rec.orientation = quat_of(bs.rotation);
  rec.velocity = bs.velocity;
  rec.angular_velocity = bs.angular_velocity;
  rec.floor_contacts = floor_contacts;
  rec.body_contacts = contact_points_[b];
  rec.grasp_area = 0.0;
  rec.torsion = 0.0;
  rec.twist = 0.0;
  return rec;
}

// Grasp rules on the residual torque (paper, 3.2): gravity drop or gimbal about the axis of a
// two-finger grasp. `contact` is the wrench of the floor and the other bodies.
void Simulation::apply_grasp_rules(int b, double pitch_change, const Wrench& contact, BodyState& bs, Vec3& torque,
                                   BodyRecord& rec) {
  if (model_.grasp.torsion == Torsion::kNone) return;
  const TwoPointGrasp grasp = two_point_grasp(model_, state_, b);
  if (!grasp.held) return;
  rec.grasp_area = grasp.area;
  const double dt = 1.0 / model_.rates.physics;
  if (model_.grasp.torsion == Torsion::kGravityDrop) {
    rec.torsion = gravity_drop(model_, b, grasp, dt, contact.force, contact.torque, bs, torque, rec.twist);
  } else if (grasp.first == model_.grasp.gimbal_finger || grasp.second == model_.grasp.gimbal_finger) {
    TwoPointGrasp toward_other = grasp;   // u from the gimbal finger to the other one
    if (grasp.second == model_.grasp.gimbal_finger) toward_other.axis = -grasp.axis;
    rec.twist = gimbal_twist(model_, b, toward_other, pitch_change, bs, torque);
  }
}

void Simulation::mark_stepped(BodyState& bs) const {
  bs.position_before_step = bs.position;
  bs.rotation_before_step = bs.rotation;
  bs.stepped_at = state_.tick;
}

// After a body's step: clear its finger window, flag a diverged state, count it towards sleep.
void Simulation::finish_body_step(int b, TickRecord& record) {
  BodyState& bs = state_.bodies[b];
  bs.window_force.setZero();
  bs.window_torque.setZero();
  const bool sane = bs.position.allFinite() && bs.rotation.allFinite() &&
                    bs.velocity.squaredNorm() <= kDivergedSpeed * kDivergedSpeed &&
                    bs.angular_velocity.squaredNorm() <= kDivergedAngularSpeed * kDivergedAngularSpeed;
  if (!sane && record.diverged_body < 0) record.diverged_body = b;
  if (model_.sleep.enabled) {
    // Still when both speeds are under their thresholds after the step; asleep after
    // sleep_steps such steps in a row, with its velocities zeroed.
    const int sleep_steps = static_cast<int>(std::ceil(model_.sleep.time * model_.rates.physics));
    const bool still = bs.velocity.norm() <= model_.sleep.linear_speed &&
                       bs.angular_velocity.norm() <= model_.sleep.angular_speed;
    bs.still_steps = still ? bs.still_steps + 1 : 0;
    if (bs.still_steps >= sleep_steps && !held_by_finger(state_, b)) {
      bs.asleep = true;
      bs.still_steps = 0;
      bs.velocity.setZero();
      bs.angular_velocity.setZero();
    }
  }
}

}  // namespace graspsim
