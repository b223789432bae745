// The implicit physics stage (implicit_stage.hpp): couplings, loads and rules, the island solve,
// then each body's move.
#include "graspsim/engine/implicit_stage.hpp"

#include <algorithm>
#include <cmath>

#include "graspsim/engine/body_step.hpp"
#include "graspsim/engine/finger_contact.hpp"
#include "graspsim/engine/floor_points.hpp"
#include "graspsim/engine/integrate.hpp"
#include "graspsim/engine/local_model.hpp"

namespace graspsim {

ImplicitStage::ImplicitStage(const Model& model) : solve_(model) {
  const std::size_t n = model.bodies.size();
  awake_.resize(n);
  v0_.resize(n);
  w0_.resize(n);
  external_force_.resize(n);
  external_torque_.resize(n);
  contact_wrench_.resize(n);
  rules_.resize(n);
  floor_points_.resize(n);
  body_points_.resize(n);
  history_.order = model.implicit_order;
  history_.valid.resize(n);
  history_.signature.resize(n);
  history_.steps.resize(n);
  couplings_.reserve(contact_room(model));
  solve_.reserve(contact_room(model));
}

void ImplicitStage::step(const Model& model, State& state, ContactGather& contacts, const Input& input,
                         const std::vector<Vec3>& finger_point, std::int64_t ticks_per_step, double pitch_change,
                         bool record_contacts, TickRecord& record) {
  const double h = 1.0 / model.rates.physics;
  couplings_.clear();
  finger_couplings(model, state, input, finger_point, ticks_per_step);
  contacts.gather(model, state, h, couplings_, floor_points_, body_points_);
  loads(model, state, ticks_per_step, pitch_change);
  solve_.solve(StepProblem{model, state, couplings_, awake_, v0_, w0_, external_force_, external_torque_, rules_,
                           history_, h});
  keep_modes(model, state);
  if (record_contacts) record_points(record);
  for (std::size_t b = 0; b < model.bodies.size(); ++b) body_step(model, state, static_cast<int>(b), record);
}

// A finger in contact: its force over the window, its spring (pad and surface in series) and
// damper about it, and its friction cone, as a floor point's (the solve decides whether it holds,
// slides or lets go: a sliding finger's friction applied as it was would flip a light body's spin
// every step). The spring's far end is the HIP, taken to go on at its mean velocity over the last
// window (the hand's motion is not known ahead; taking it to stand still would hold the body back
// by k h v_hand).
void ImplicitStage::finger_couplings(const Model& model, State& state, const Input& input,
                                     const std::vector<Vec3>& finger_point, std::int64_t ticks_per_step) {
  const double h = 1.0 / model.rates.physics;
  const double per_tick = 1.0 / static_cast<double>(ticks_per_step);
  for (std::size_t f = 0; f < model.fingers.size(); ++f) {
    FingerState& fs = state.fingers[f];
    const Vec3& hip = input.fingers[f].hip;
    const Vec3 hip_velocity = fs.has_last_physics ? Vec3((hip - fs.hip_at_last_physics) / h) : Vec3::Zero();
    fs.hip_at_last_physics = hip;
    fs.has_last_physics = true;
    const Vec3 window = fs.window_force * per_tick;   // N, on the body: the window's mean
    fs.window_force.setZero();
    if (fs.phase == ContactPhase::kFree || fs.body < 0 || window.isZero(0.0)) continue;
    const BodyState& bs = state.bodies[fs.body];
    const double k = finger_contact_pair(model, static_cast<int>(f), fs.body).stiffness;   // N/m
    const double c = model.fingers[f].damping;                                          // N s/m
    // The window's forces were measured on the body as the fast loops saw it (local_model.hpp),
    // `lead` ahead of this step's pose on average: the spring's force at the step's pose is the
    // window's plus k lead u0, and the next window, seen `lead` ahead of the end pose, feels the
    // end velocity over h + lead (Coupling; derivation in engine/README.md, "The local model").
    const Pose seen = fast_loop_pose(model, bs, state.tick);
    const Vec3 point = bs.rotation * (seen.rotation.transpose() * (finger_point[f] - seen.position)) + bs.position;
    Coupling cp;
    cp.source = Coupling::Source::kFinger;
    cp.slot = static_cast<int>(f);
    cp.b = fs.body;
    cp.point = point;
    cp.arm = point - bs.position;
    cp.normal = -(bs.rotation * fs.normal);   // into the body
    cp.world_velocity = hip_velocity;
    cp.force = window;
    cp.lead = fast_loop_lead(model);
    cp.k_n = cp.k_t = k;
    cp.c_n = cp.c_t = c;
    cp.mu = fs.friction_mu;
    cp.viscous = fs.viscous_force;
    couplings_.push_back(cp);
  }
}

// Each body's start, its load over the step, and its grasp rule. The fingers' forces enter through
// their couplings: what is left of the bodies' windows is what fingers pushed that are no longer
// in contact, and the torque of each finger's force about where its contact point is now, not where
// it was when the GO last moved.
void ImplicitStage::loads(const Model& model, const State& state, std::int64_t ticks_per_step, double pitch_change) {
  const double h = 1.0 / model.rates.physics;
  const double per_tick = 1.0 / static_cast<double>(ticks_per_step);
  const std::size_t nb = model.bodies.size();
  for (std::size_t b = 0; b < nb; ++b) {
    const BodyParams& bp = model.bodies[b];
    const BodyState& bs = state.bodies[b];
    awake_[b] = bs.asleep ? 0 : 1;
    v0_[b] = bs.velocity;
    w0_[b] = bs.angular_velocity + gyroscopic_change(bp, model.gyroscopic, bs, h);
    external_force_[b] = bs.window_force * per_tick + bp.mass * model.gravity;
    external_torque_[b] = bs.window_torque * per_tick;
    // What BDF2 needs to know of the last step: whether the body took it at the last physics tick.
    history_.valid[b] = !bs.asleep && bs.stepped_at >= 0 && bs.stepped_at + ticks_per_step == state.tick;
    history_.signature[b] = bs.island_signature;
    history_.steps[b] = bs.island_steps;
  }
  const bool rules = model.grasp.torsion != Torsion::kNone;   // else rules_ stay as constructed: none
  if (rules) std::fill(contact_wrench_.begin(), contact_wrench_.end(), Wrench{});
  for (const Coupling& c : couplings_) {
    if (c.source == Coupling::Source::kFinger) {
      external_force_[c.b] -= c.force;
      external_torque_[c.b] -= c.arm.cross(c.force);
      continue;
    }
    if (!rules) continue;
    // The floor's and other bodies' push at the start of the step, pushing only, for the rules.
    const Vec3 f = std::max(0.0, c.normal.dot(c.force)) * c.normal;
    contact_wrench_[c.b].force += f;
    contact_wrench_[c.b].torque += c.arm.cross(f);
    if (c.a >= 0) {
      contact_wrench_[c.a].force -= f;
      contact_wrench_[c.a].torque -= (c.point - state.bodies[c.a].position).cross(f);
    }
  }
  for (std::size_t b = 0; rules && b < nb; ++b) {
    rules_[b] = awake_[b] ? plan_axis_rule(model, state, static_cast<int>(b), h, pitch_change,
                                           contact_wrench_[b].force, contact_wrench_[b].torque)
                          : AxisRule{};
  }
}

// What the solve decided, kept in the State for the next step: which points slip; and how many
// floor and body points each body has in the solved set (its record's counts).
void ImplicitStage::keep_modes(const Model& model, State& state) {
  std::fill(floor_points_.begin(), floor_points_.end(), 0);
  std::fill(body_points_.begin(), body_points_.end(), 0);
  (void)model;
  for (std::size_t i = 0; i < couplings_.size(); ++i) {
    const Coupling& c = couplings_[i];
    if (c.source == Coupling::Source::kFinger) continue;
    const CouplingMode mode = solve_.mode(i);
    const bool slipping = mode == CouplingMode::kSlip;
    const int in_set = mode != CouplingMode::kOff ? 1 : 0;
    if (c.source == Coupling::Source::kFloor) {
      state.bodies[c.b].floor_contacts[c.slot].slipping = slipping;
      floor_points_[c.b] += in_set;
    } else {
      state.pairs[c.pair].points[c.slot].slipping = slipping;
      body_points_[c.a] += in_set;
      body_points_[c.b] += in_set;
    }
  }
}

// The floor and body points of the solved set with the forces found, in the couplings' order (as
// BodyRecord's counts count them).
void ImplicitStage::record_points(TickRecord& record) const {
  for (std::size_t i = 0; i < couplings_.size(); ++i) {
    const Coupling& c = couplings_[i];
    if (c.source == Coupling::Source::kFinger || solve_.mode(i) == CouplingMode::kOff) continue;
    record.contacts.push_back(ContactRecord{c.source == Coupling::Source::kFloor ? kFloor : c.a, c.b, c.point,
                                            c.normal, solve_.force(i)});
  }
}

// One body after the solve: its velocity change as the force and torque that make it, its grasp
// rule's rate about the axis set directly, the move, then the rule's turn. The dead band (section
// 5) acts on the rule's torque about the axis only (plan_axis_rule): the paper's band stops the
// residual torque reversing at every explicit step, which this step never does, and on the whole
// torque it would throw away the solve's damping of a body turning slowly, keeping it turning.
void ImplicitStage::body_step(const Model& model, State& state, int b, TickRecord& record) {
  const BodyParams& bp = model.bodies[b];
  BodyState& bs = state.bodies[b];
  if (bs.asleep) {
    record_sleeping_body(state, b, body_points_[b], record);
    return;
  }
  const double h = 1.0 / model.rates.physics;
  BodyRecord& rec = record_body_state(state, b, floor_points_[b], body_points_[b], record);
  const AxisRule& rule = rules_[b];
  Vec3 w0 = w0_[b];
  if (rule.active) w0 += (rule.rate - w0.dot(rule.grasp.axis)) * rule.grasp.axis;
  if (rule.grasp.held) rec.grasp_area = rule.grasp.area;
  rec.torsion = rule.torsion;
  rec.twist = rule.turn;
  const Mat3& R = bs.rotation;
  const Vec3 force = (bp.mass / h) * (solve_.velocity(b) - v0_[b]);
  const Vec3 torque = (R * bp.inertia.asDiagonal() * R.transpose()) * ((solve_.angular_velocity(b) - w0) / h);
  rec.force = force;
  rec.torque = torque;
  const Vec3 v_start = bs.velocity, w_start = bs.angular_velocity;
  if (solve_.second_order(b)) {
    mark_stepped(bs, state.tick);
    move_body_bdf2(bs, solve_.velocity(b), solve_.angular_velocity(b), solve_.mean_velocity(b),
                   solve_.mean_angular_velocity(b), h);
  } else {
    bs.angular_velocity = w0;
    mark_stepped(bs, state.tick);
    move_body(bp, bs, force, torque, h);
    turn_about_axis(rule.grasp, rule.turn, bs);
  }
  if (model.implicit_order == 2) {
    bs.velocity_before_step = v_start;
    bs.angular_velocity_before_step = w_start;
    bs.island_steps = solve_.signature(b) == bs.island_signature ? bs.island_steps + 1 : 1;
    bs.island_signature = solve_.signature(b);
  }
  finish_body_step(model, state, b, record);
}

}  // namespace graspsim
