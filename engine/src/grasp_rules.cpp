// Torsion about a two-finger grasp axis (paper, section 3.2) and the torque dead band (5).
#include "graspsim/engine/grasp_rules.hpp"

#include <cmath>

#include "graspsim/engine/collision.hpp"
#include "graspsim/engine/finger_contact.hpp"

namespace graspsim {
namespace {

// Sets the body's rotation rate about the axis through `point` along unit `u` to `w_u`, as a
// hinge: the velocity of the points on the axis does not change, so the centre of mass moves
// on a circle about the axis. v_point = v + w x (point - c) is kept:
//   v' = v + (w - w') x (point - c) = v + (w.u - w_u) u x (point - c).
void set_hinge_rate(const Vec3& point, const Vec3& u, double w_u, BodyState& bs) {
  const double change = bs.angular_velocity.dot(u) - w_u;
  bs.angular_velocity -= change * u;
  bs.velocity += (change * u).cross(point - bs.position);
}

// Moment of inertia about the axis through `point` along unit `u` (parallel-axis theorem):
// J_axis = u^T (R Jp R^T) u + m |p_perp|^2, p = c - point.
double axis_inertia(const BodyParams& bp, const BodyState& bs, const Vec3& point, const Vec3& u) {
  const Vec3 u_body = bs.rotation.transpose() * u;
  const Vec3 p = bs.position - point;
  const double p_perp2 = p.squaredNorm() - p.dot(u) * p.dot(u);
  return u_body.dot(bp.inertia.cwiseProduct(u_body)) + bp.mass * p_perp2;
}

}  // namespace

TwoPointGrasp two_point_grasp(const Model& /*model*/, const State& state, int body) {
  TwoPointGrasp g;
  int count = 0;
  for (std::size_t f = 0; f < state.fingers.size(); ++f) {
    const FingerState& fs = state.fingers[f];
    if (fs.phase == ContactPhase::kFree || fs.body != body) continue;
    if (++count == 1) g.first = static_cast<int>(f);
    else if (count == 2) g.second = static_cast<int>(f);
  }
  if (count != 2) return g;
  const FingerState& first = state.fingers[g.first];
  const FingerState& second = state.fingers[g.second];
  // A grasp squeezes from opposite sides: two fingers whose contact normals (stored at the last
  // haptic tick, in the body frame) do not oppose, pressing one face or adjacent ones, hold
  // nothing between them. Any shape: the normals are the surface's at the surface points.
  if (first.normal.dot(second.normal) >= 0.0) return g;
  const BodyState& bs = state.bodies[body];
  const Vec3 a = bs.rotation * first.god_object + bs.position;
  const Vec3 b = bs.rotation * second.god_object + bs.position;
  const double length = (b - a).norm();
  if (length <= 1e-6) return g;
  const double r = std::min(first.friction_radius, second.friction_radius);
  g.held = true;
  g.go_first = a;
  g.axis = (b - a) / length;
  g.area = M_PI * r * r;
  return g;
}

namespace {

// Removes from `torque` the angular acceleration it would give about u, so that the rate set
// about the axis survives the integration when u is not a principal axis: with
// alpha = I^-1 T (I = R Jp R^T), T' = T - (alpha . u) I u gives alpha' = alpha - (alpha . u) u.
void keep_axis_rate(const BodyParams& bp, const BodyState& bs, const Vec3& u, Vec3& torque) {
  const Mat3& R = bs.rotation;
  const Vec3 alpha = R * (R.transpose() * torque).cwiseQuotient(bp.inertia);
  const Vec3 i_u = R * bp.inertia.cwiseProduct(R.transpose() * u);
  torque -= alpha.dot(u) * i_u;
}

// Locks the rotation about the grasp axis: the residual about u removed, the rate about u set
// to `w_u` as a hinge through the first god-object, and kept through the integration.
void hinge(const BodyParams& bp, const TwoPointGrasp& grasp, double w_u, BodyState& bs, Vec3& torque) {
  torque -= torque.dot(grasp.axis) * grasp.axis;
  set_hinge_rate(grasp.go_first, grasp.axis, w_u, bs);
  keep_axis_rate(bp, bs, grasp.axis, torque);
}

}  // namespace

void turn_about_axis(const TwoPointGrasp& grasp, double angle, BodyState& bs) {
  if (angle == 0.0) return;
  const Mat3 turn = Eigen::AngleAxisd(angle, grasp.axis).toRotationMatrix();
  bs.rotation = turn * bs.rotation;
  bs.position = grasp.go_first + turn * (bs.position - grasp.go_first);
}

AxisRule plan_axis_rule(const Model& model, const State& state, int body, double dt, double pitch_change,
                        const Vec3& contact_force, const Vec3& contact_torque) {
  AxisRule rule;
  if (model.grasp.torsion == Torsion::kNone) return rule;
  TwoPointGrasp grasp = two_point_grasp(model, state, body);
  if (!grasp.held) return rule;
  const BodyState& bs = state.bodies[body];
  const BodyParams& bp = model.bodies[body];
  if (model.grasp.torsion == Torsion::kGimbal) {
    const int g = model.grasp.gimbal_finger;
    if (grasp.first != g && grasp.second != g) return rule;
    if (grasp.second == g) grasp.axis = -grasp.axis;   // u from the gimbal finger to the other one
    rule.grasp = grasp;
    if (!(grasp.area > model.grasp.critical_area)) return rule;   // recorded, not constrained
    rule.active = true;
    rule.turn = pitch_change;
    return rule;
  }
  rule.grasp = grasp;
  rule.active = true;
  if (!(grasp.area < model.grasp.critical_area)) return rule;   // the pads hold: no rotation
  const Vec3& u = grasp.axis;
  const Vec3 p = bs.position - grasp.go_first;   // from a contact point to the centre of mass
  const double drop = p.cross(bp.mass * model.gravity * (1.0 - grasp.area / model.grasp.critical_area)).dot(u);
  double turning = drop + (contact_torque + p.cross(contact_force)).dot(u);
  if (std::abs(turning) <= model.grasp.dead_band) turning = 0.0;   // section 5, about u too
  rule.torsion = turning;
  // Implicit in the turn too: the gravity torque's stiffness about the axis, K = -dT/dtheta =
  // -[(u x p) x m g s] . u (p turns as u x p), enters as backward Euler does, so the rule cannot
  // overshoot the hanging position however small the pads' c_t or slow the physics (the paper's
  // explicit turn overshoots once h K / c_t > 1 and grows once it passes 2).
  const Vec3 weight = bp.mass * model.gravity * (1.0 - grasp.area / model.grasp.critical_area);   // N
  const double stiffness = std::max(0.0, -(u.cross(p).cross(weight)).dot(u));                     // N m/rad
  if (model.grasp.torsional_damping > 0.0) {
    rule.turn = dt * turning / (model.grasp.torsional_damping + dt * stiffness);
  } else {
    const double inertia = axis_inertia(bp, bs, grasp.go_first, u);   // kg m^2
    rule.rate = (inertia * bs.angular_velocity.dot(u) + dt * turning) / (inertia + dt * dt * stiffness);
  }
  return rule;
}


double gravity_drop(const Model& model, int body, const TwoPointGrasp& grasp, double dt,
                    const Vec3& floor_force, const Vec3& floor_torque, BodyState& bs, Vec3& torque,
                    double& turned) {
  const Vec3& u = grasp.axis;
  const BodyParams& bp = model.bodies[body];
  const double c_t = model.grasp.torsional_damping;
  turned = 0.0;
  if (!(grasp.area < model.grasp.critical_area)) {   // the pads hold: no rotation about u
    hinge(bp, grasp, 0.0, bs, torque);
    return 0.0;
  }
  // About the axis: the paper's scaled gravity torque, plus what else pushes the body (the
  // floor's torque about the axis point: T_c + (c - GO) x F); the fingers hold the axis.
  const Vec3 p = bs.position - grasp.go_first;   // from a contact point to the centre of mass
  const double drop = p.cross(bp.mass * model.gravity * (1.0 - grasp.area / model.grasp.critical_area)).dot(u);
  double turning = drop + (floor_torque + p.cross(floor_force)).dot(u);
  if (std::abs(turning) <= model.grasp.dead_band) turning = 0.0;   // section 5, about u too
  if (c_t > 0.0) {
    // Quasi-static: the pads' torsional friction sets the rate, T_u / c_t, and the step turns the
    // body by dt T_u / c_t about the axis, exactly (no rate is left about u to carry over).
    hinge(bp, grasp, 0.0, bs, torque);
    turned = dt * turning / c_t;
    turn_about_axis(grasp, turned, bs);
    return turning;
  }
  // Inertial: the rate about the axis integrates T_u over the inertia about the axis.
  hinge(bp, grasp, bs.angular_velocity.dot(u) + dt * turning / axis_inertia(bp, bs, grasp.go_first, u), bs, torque);
  return turning;
}

double gimbal_twist(const Model& model, int body, const TwoPointGrasp& grasp, double pitch_change,
                    BodyState& bs, Vec3& torque) {
  if (!(grasp.area > model.grasp.critical_area)) return 0.0;
  hinge(model.bodies[body], grasp, 0.0, bs, torque);
  if (pitch_change == 0.0) return 0.0;
  turn_about_axis(grasp, pitch_change, bs);
  return pitch_change;
}

}  // namespace graspsim
