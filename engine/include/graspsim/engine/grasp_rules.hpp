// Grasp rules on a body's residual wrench: torsion about a two-finger grasp axis (paper,
// section 3.2) and the torque dead band against oscillation (section 5).
#pragma once

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

// A body held by exactly two fingers on opposing faces: the axis through their god-objects.
struct TwoPointGrasp {
  bool held = false;                  // exactly two fingers touch the body
  int first = -1, second = -1;        // the two fingers, in finger order
  Vec3 go_first{0.0, 0.0, 0.0};       // m, world: god-object of `first`
  Vec3 axis{0.0, 0.0, 0.0};           // 1, world: u, unit, from the first GO to the second
  double area = 0.0;                  // m^2: A = pi r^2 of the smaller friction circle of the
                                      //      two at the last haptic tick
};

// The two-point grasp of body b, if exactly two fingers touch it, on faces whose normals oppose,
// with god-objects more than 1 um apart (else `held` is false).
TwoPointGrasp two_point_grasp(const Model& model, const State& state, int body);

// Section 3.2, solution 2 (gravity-induced drop). The body turns about the grasp axis as about a
// hinge through the god-objects (the paper's section 6 suggests taking accelerations about a
// point near the contacts; about the centre of mass the soft finger springs would have to supply
// the pivot force and a swinging body tears out of the grasp):
//   A <  A_crit: w_u += dt T_u / J_axis, T_u = [p x m g (1 - A/A_crit)] . u plus the floor's
//                torque about the axis, p = centre - GO, J_axis the moment of inertia about the
//                axis; the dead band applies to T_u as to the residual (section 5);
//                with the pads' torsional friction c_t > 0 (grasp.torsional_damping) the turn
//                is quasi-static instead: the body is turned by dt T_u / c_t about the axis
//                (rigidly, as by the gimbal) and keeps no rate about u, so a torque in the
//                dead band stops it (section 5; see engine/README.md);
//   A >= A_crit: w_u = 0, no rotation about the axis.
// The residual torque is replaced about u, and corrected so that it adds no angular
// acceleration about u (u need not be a principal axis); the velocity is corrected so that the
// axis itself does not move. Returns T_u (N m; 0 above A_crit); `turned` (rad) is the
// quasi-static turn of this step (0 when inertial).
double gravity_drop(const Model& model, int body, const TwoPointGrasp& grasp, double dt,
                    const Vec3& floor_force, const Vec3& floor_torque, BodyState& bs, Vec3& torque,
                    double& turned);

// Section 3.2, solution 1 (instrumented gimbal): once A > A_crit, the body turns about the axis
// through the god-objects by the change of the gimbal finger's pitch since the last physics
// step, positively about u for a positive pitch (the caller points u from the gimbal finger to
// the other, so the sense does not depend on the fingers' order); its own rotation rate about
// that axis is set to zero, as above. Returns the angle turned (rad).
double gimbal_twist(const Model& model, int body, const TwoPointGrasp& grasp, double pitch_change,
                    BodyState& bs, Vec3& torque);

// The same two rules for the implicit step, which cannot take a rate set after its solve: the
// rule is planned before it, as the rate the body must turn at about the grasp axis (a
// constraint of the solve, w1 . u = rate) and a turn to make after the move. The gravity drop's
// turn or rate is backward Euler in the angle about the axis: with K = -dT_u/dtheta >= 0,
//   quasi-static  turn = h T_u / (c_t + h K)       inertial  w_u = (J w_u + h T_u) / (J + h^2 K)
struct AxisRule {
  bool active = false;       // a two-point grasp under a torsion rule constrains the body
  TwoPointGrasp grasp;       // u: grasp.axis, through grasp.go_first
  double rate = 0.0;         // rad/s: w . u at the end of the step
  double turn = 0.0;         // rad: rigid turn about the axis after the move (gimbal pitch, or
                             //      the quasi-static gravity drop dt T_u / c_t)
  double torsion = 0.0;      // N m: T_u, the gravity drop's torque about the axis (recorded)
};
// `contact_force` and `contact_torque` (about the centre of mass): the floor's and other
// bodies' push at the start of the step, which turns the body about the axis with gravity.
AxisRule plan_axis_rule(const Model& model, const State& state, int body, double dt, double pitch_change,
                        const Vec3& contact_force, const Vec3& contact_torque);

// Turns the body, orientation and centre, by `angle` about the grasp axis through the first
// god-object (a rigid turn: the points on the axis stay put).
void turn_about_axis(const TwoPointGrasp& grasp, double angle, BodyState& bs);

// Section 5: T = 0 when |T| <= T_crit.
inline void dead_band(double t_crit, Vec3& torque) {
  if (t_crit > 0.0 && torque.squaredNorm() <= t_crit * t_crit) torque.setZero();
}

}  // namespace graspsim
