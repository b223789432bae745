// The physics stage under integrator = "implicit": every contact point as a spring-damper about
// this tick's state, each island of touching bodies solved at once, then the grasp rules and the
// move (engine/README.md, "Integrators").
#include <algorithm>
#include <cmath>

#include "graspsim/engine/finger_contact.hpp"
#include "graspsim/engine/grasp_rules.hpp"
#include "graspsim/engine/integrate.hpp"
#include "graspsim/engine/simulation.hpp"

namespace graspsim {

// The couplings of this step: fingers pushing on a body, floor points, body-body points.
void Simulation::implicit_contacts(const Input& input) {
  const double h = 1.0 / model_.rates.physics;
  couplings_.clear();
  std::fill(contact_points_.begin(), contact_points_.end(), 0);
  // A finger in contact, pushing: its spring (pad and surface in series) and damper, whole while
  // it sticks, along the normal alone while its force is held on the cone. Its force over the
  // window is in the body's window already; the coupling adds how it changes as the body moves,
  // and as the HIP goes on moving at its mean velocity over the last window (the hand's motion is
  // not known ahead; taking it to stand still would hold the body back by k h v_hand).
  for (std::size_t f = 0; f < model_.fingers.size(); ++f) {
    FingerState& fs = state_.fingers[f];
    const Vec3& hip = input.fingers[f].hip;
    const Vec3 hip_velocity = fs.has_last_physics ? Vec3((hip - fs.hip_at_last_physics) / h) : Vec3::Zero();
    fs.hip_at_last_physics = hip;
    fs.has_last_physics = true;
    if (fs.phase == ContactPhase::kFree || fs.body < 0 || finger_force_[f].isZero(0.0)) continue;
    const BodyState& bs = state_.bodies[fs.body];
    const double k = finger_contact_pair(model_, static_cast<int>(f), fs.body).stiffness;   // N/m
    const double c = model_.fingers[f].damping;                                          // N s/m
    Coupling cp;
    cp.source = Coupling::Source::kFinger;
    cp.slot = static_cast<int>(f);
    cp.b = fs.body;
    cp.point = finger_point_[f];
    cp.world_velocity = hip_velocity;
    cp.normal = -(bs.rotation * fs.normal);   // into the body
    cp.force = Vec3::Zero();
    cp.k_n = k;
    cp.c_n = c;
    const bool sticking = fs.phase == ContactPhase::kStick;
    cp.k_t = sticking ? k : 0.0;
    cp.c_t = sticking ? c : 0.0;
    couplings_.push_back(cp);
  }
  if (model_.floor.enabled) {
    const double g = model_.gravity.norm();   // m/s^2
    for (std::size_t b = 0; b < model_.bodies.size(); ++b) {
      BodyState& bs = state_.bodies[b];
      if (bs.asleep) continue;
      // How far the body's lowest point can travel towards the floor in this step.
      const double approach = h * (std::max(0.0, -bs.velocity.z()) + bs.angular_velocity.norm() * floor_reach_[b] + h * g);
      if (bs.position.z() - floor_reach_[b] - approach > model_.floor.height) {
        if (!floor_clear_[b]) {
          for (VertexContact& vc : bs.floor_contacts) vc.active = false;
          floor_clear_[b] = 1;
        }
        continue;
      }
      floor_clear_[b] = floor_couplings(model_, static_cast<int>(b), bs, h, couplings_) == 0 ? 1 : 0;
    }
  }
  body_contacts_.couplings(model_, state_, couplings_, contact_points_);
}

// Solves every island for its velocities at the end of the step, then keeps what the solve
// decided: which points slip, how many floor points push, and the contact wrench on each body
// (for the grasp rules).
void Simulation::implicit_solve() {
  const double h = 1.0 / model_.rates.physics;
  const double per_tick = 1.0 / static_cast<double>(divisors_.physics);
  const std::size_t nb = model_.bodies.size();
  for (std::size_t b = 0; b < nb; ++b) {
    const BodyParams& bp = model_.bodies[b];
    const BodyState& bs = state_.bodies[b];
    awake_[b] = bs.asleep ? 0 : 1;
    v0_[b] = bs.velocity;
    w0_[b] = bs.angular_velocity + gyroscopic_change(bp, model_.gyroscopic, bs, h);
    external_force_[b] = bs.window_force * per_tick + bp.mass * model_.gravity;
    external_torque_[b] = bs.window_torque * per_tick;
  }
  implicit_.solve(model_, state_, couplings_, awake_, v0_, w0_, external_force_, external_torque_, h);

  std::fill(contact_wrench_.begin(), contact_wrench_.end(), Wrench{});
  std::fill(floor_points_.begin(), floor_points_.end(), 0);
  const int n = static_cast<int>(nb);
  for (std::size_t i = 0; i < couplings_.size(); ++i) {
    const Coupling& c = couplings_[i];
    if (c.source == Coupling::Source::kFinger) continue;
    const CouplingMode mode = implicit_.mode(i);
    const bool slipping = mode == CouplingMode::kSlip;
    if (c.source == Coupling::Source::kFloor) {
      state_.bodies[c.b].floor_contacts[c.slot].slipping = slipping;
      if (mode != CouplingMode::kOff) ++floor_points_[c.b];
    } else {
      state_.pairs[pair_index(c.a, c.b, n)].points[c.slot].slipping = slipping;
    }
    const Vec3& f = implicit_.force(i);
    contact_wrench_[c.b].force += f;
    contact_wrench_[c.b].torque += (c.point - state_.bodies[c.b].position).cross(f);
    if (c.a >= 0) {
      contact_wrench_[c.a].force -= f;
      contact_wrench_[c.a].torque -= (c.point - state_.bodies[c.a].position).cross(f);
    }
  }
}

// One body after the solve: its velocity change as the force and torque that make it, the grasp
// rules and the dead band on that torque, then the move.
void Simulation::implicit_body_step(int b, double pitch_change, TickRecord& record) {
  const BodyParams& bp = model_.bodies[b];
  BodyState& bs = state_.bodies[b];
  if (bs.asleep) {
    record_sleeping(b, record);
    return;
  }
  const double h = 1.0 / model_.rates.physics;
  BodyRecord& rec = record_state(b, floor_points_[b], record);
  const Mat3& R = bs.rotation;
  const Vec3 force = (bp.mass / h) * (implicit_.velocity(b) - v0_[b]);
  Vec3 torque = (R * bp.inertia.asDiagonal() * R.transpose()) * ((implicit_.angular_velocity(b) - w0_[b]) / h);
  bs.angular_velocity = w0_[b];
  apply_grasp_rules(b, pitch_change, contact_wrench_[b], bs, torque, rec);
  dead_band(model_.grasp.dead_band, torque);
  rec.force = force;
  rec.torque = torque;
  mark_stepped(bs);
  move_body(bp, bs, force, torque, h);
  finish_body_step(b, record);
}

}  // namespace graspsim
