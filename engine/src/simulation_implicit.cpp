// The physics stage under integrator = "implicit": every contact point as a spring-damper about
// this tick's state, each island of touching bodies solved at once, then the grasp rules and the
// move (engine/README.md, "Integrators").
#include <algorithm>
#include <cmath>

#include "graspsim/engine/finger_contact.hpp"
#include "graspsim/engine/grasp_rules.hpp"
#include "graspsim/engine/integrate.hpp"
#include "graspsim/engine/local_model.hpp"
#include "graspsim/engine/simulation.hpp"

namespace graspsim {

// The couplings of this step: fingers pushing on a body, floor points, body-body points.
void Simulation::implicit_contacts(const Input& input) {
  const double h = 1.0 / model_.rates.physics;
  couplings_.clear();
  std::fill(contact_points_.begin(), contact_points_.end(), 0);
  // A finger in contact: its force over the window, its spring (pad and surface in series) and
  // damper about it, and its friction cone, as a floor point's (the solve decides whether it
  // holds, slides or lets go: a sliding finger's friction applied as it was would flip a light
  // body's spin every step). The spring's far end is the HIP, taken to go on at its mean velocity
  // over the last window (the hand's motion is not known ahead; taking it to stand still would
  // hold the body back by k h v_hand).
  const double per_tick = 1.0 / static_cast<double>(divisors_.physics);
  for (std::size_t f = 0; f < model_.fingers.size(); ++f) {
    FingerState& fs = state_.fingers[f];
    const Vec3& hip = input.fingers[f].hip;
    const Vec3 hip_velocity = fs.has_last_physics ? Vec3((hip - fs.hip_at_last_physics) / h) : Vec3::Zero();
    fs.hip_at_last_physics = hip;
    fs.has_last_physics = true;
    const Vec3 window = fs.window_force * per_tick;   // N, on the body: the window's mean
    fs.window_force.setZero();
    if (fs.phase == ContactPhase::kFree || fs.body < 0 || window.isZero(0.0)) continue;
    const BodyState& bs = state_.bodies[fs.body];
    const double k = finger_contact_pair(model_, static_cast<int>(f), fs.body).stiffness;   // N/m
    const double c = model_.fingers[f].damping;                                          // N s/m
    // The window's forces were measured on the body as the fast loops saw it (local_model.hpp),
    // `lead` ahead of this step's pose on average: the spring's force at the step's pose is the
    // window's plus k lead u0, and the next window, seen `lead` ahead of the end pose, feels the
    // end velocity over h + lead (Coupling; derivation in engine/README.md, "The local model").
    const Pose seen = fast_loop_pose(model_, bs, state_.tick);
    const Vec3 point = bs.rotation * (seen.rotation.transpose() * (finger_point_[f] - seen.position)) + bs.position;
    Coupling cp;
    cp.source = Coupling::Source::kFinger;
    cp.slot = static_cast<int>(f);
    cp.b = fs.body;
    cp.point = point;
    cp.normal = -(bs.rotation * fs.normal);   // into the body
    cp.world_velocity = hip_velocity;
    cp.force = window;
    cp.lead = fast_loop_lead(model_);
    cp.k_n = cp.k_t = k;
    cp.c_n = cp.c_t = c;
    cp.mu = fs.friction_mu;
    cp.viscous = fs.viscous_force;
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
      floor_clear_[b] = floor_couplings(model_, static_cast<int>(b), floor_pairs_[b], bs, h, floor_reach_[b], couplings_) == 0 ? 1 : 0;
    }
  }
  body_contacts_.couplings(model_, state_, couplings_, contact_points_);
}

// Plans each body's grasp rule, solves every island for its velocities at the end of the step,
// then keeps what the solve decided: which points slip and how many floor points push.
void Simulation::implicit_solve(double pitch_change) {
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
    // What BDF2 needs to know of the last step: whether the body took it at the last physics tick.
    history_.valid[b] = !bs.asleep && bs.stepped_at >= 0 && bs.stepped_at + divisors_.physics == state_.tick;
    history_.signature[b] = bs.island_signature;
    history_.steps[b] = bs.island_steps;
  }
  // The fingers' forces enter through their couplings: what is left of the bodies' windows is
  // what fingers pushed that are no longer in contact, and the torque of each finger's force
  // about where its contact point is now, not where it was when the GO last moved.
  const bool rules = model_.grasp.torsion != Torsion::kNone;   // else rules_ stay as constructed: none
  if (rules) std::fill(contact_wrench_.begin(), contact_wrench_.end(), Wrench{});
  for (const Coupling& c : couplings_) {
    if (c.source == Coupling::Source::kFinger) {
      external_force_[c.b] -= c.force;
      external_torque_[c.b] -= (c.point - state_.bodies[c.b].position).cross(c.force);
      continue;
    }
    if (!rules) continue;
    // The floor's and other bodies' push at the start of the step, pushing only, for the rules.
    const Vec3 f = std::max(0.0, c.normal.dot(c.force)) * c.normal;
    contact_wrench_[c.b].force += f;
    contact_wrench_[c.b].torque += (c.point - state_.bodies[c.b].position).cross(f);
    if (c.a >= 0) {
      contact_wrench_[c.a].force -= f;
      contact_wrench_[c.a].torque -= (c.point - state_.bodies[c.a].position).cross(f);
    }
  }
  for (std::size_t b = 0; rules && b < nb; ++b) {
    rules_[b] = awake_[b] ? plan_axis_rule(model_, state_, static_cast<int>(b), h, pitch_change,
                                           contact_wrench_[b].force, contact_wrench_[b].torque)
                          : AxisRule{};
    axis_active_[b] = rules_[b].active ? 1 : 0;
    axis_[b] = rules_[b].grasp.axis;
    axis_point_[b] = rules_[b].grasp.go_first;
    axis_rate_[b] = rules_[b].rate;
  }
  implicit_.solve(model_, state_, couplings_, awake_, v0_, w0_, external_force_, external_torque_, axis_active_,
                  axis_, axis_point_, axis_rate_, history_, h);

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
  }
}

// The floor and body points of the solve with the forces it found, in the couplings' order: a
// floor point only while it pushes or rubs (not kOff, as BodyRecord::floor_contacts counts), a
// body point always (as body_contacts counts; zero force when kOff).
void Simulation::record_implicit_contacts(TickRecord& record) const {
  for (std::size_t i = 0; i < couplings_.size(); ++i) {
    const Coupling& c = couplings_[i];
    if (c.source == Coupling::Source::kFinger) continue;
    if (c.source == Coupling::Source::kFloor && implicit_.mode(i) == CouplingMode::kOff) continue;
    record.contacts.push_back(ContactRecord{c.source == Coupling::Source::kFloor ? kFloor : c.a, c.b, c.point,
                                            c.normal, implicit_.force(i)});
  }
}

// One body after the solve: its velocity change as the force and torque that make it, its grasp
// rule's rate about the axis set directly, the move, then the rule's turn. The dead band (section
// 5) acts on the rule's torque about the axis only (plan_axis_rule): the paper's band stops the
// residual torque reversing at every explicit step, which this step never does, and on the whole
// torque it would throw away the solve's damping of a body turning slowly, keeping it turning.
void Simulation::implicit_body_step(int b, TickRecord& record) {
  const BodyParams& bp = model_.bodies[b];
  BodyState& bs = state_.bodies[b];
  if (bs.asleep) {
    record_sleeping(b, record);
    return;
  }
  const double h = 1.0 / model_.rates.physics;
  BodyRecord& rec = record_state(b, floor_points_[b], record);
  const AxisRule& rule = rules_[b];
  Vec3 w0 = w0_[b];
  if (rule.active) w0 += (rule.rate - w0.dot(rule.grasp.axis)) * rule.grasp.axis;
  if (rule.grasp.held) rec.grasp_area = rule.grasp.area;
  rec.torsion = rule.torsion;
  rec.twist = rule.turn;
  const Mat3& R = bs.rotation;
  const Vec3 force = (bp.mass / h) * (implicit_.velocity(b) - v0_[b]);
  Vec3 torque = (R * bp.inertia.asDiagonal() * R.transpose()) * ((implicit_.angular_velocity(b) - w0) / h);
  rec.force = force;
  rec.torque = torque;
  const Vec3 v_start = bs.velocity, w_start = bs.angular_velocity;
  if (implicit_.second_order(b)) {
    mark_stepped(bs);
    move_body_bdf2(bs, implicit_.velocity(b), implicit_.angular_velocity(b), implicit_.mean_velocity(b),
                   implicit_.mean_angular_velocity(b), h);
  } else {
    bs.angular_velocity = w0;
    mark_stepped(bs);
    move_body(bp, bs, force, torque, h);
    turn_about_axis(rule.grasp, rule.turn, bs);
  }
  if (model_.implicit_order == 2) {
    bs.velocity_before_step = v_start;
    bs.angular_velocity_before_step = w_start;
    bs.island_steps = implicit_.signature(b) == bs.island_signature ? bs.island_steps + 1 : 1;
    bs.island_signature = implicit_.signature(b);
  }
  finish_body_step(b, record);
}

}  // namespace graspsim
