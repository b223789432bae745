// The body as the fast loops see it between physics steps: a local model (Cavusoglu & Tendick,
// "Multirate simulation for high fidelity haptic interaction with deformable objects", ICRA 2000).
//
// With Model::local_model under integrator = "implicit", a body is taken to go on from its last physics step with the
// twist that step found (v_n at the centre of mass, w_n), so the haptic and servo loops see it
// move at every servo tick instead of standing still for a physics period and then jumping (the
// paper's staircase, which a hand on a Phantom feels as a buzz at the physics rate). A constant
// twist is a screw motion, tau = t - t_n (0 < tau <= 1 / physics):
//   R(t) = exp(S(w_n) tau) R_n,   p(t) = p_n + tau J(w_n tau) v_n,   v(t) = exp(S(w_n) tau) v_n,
//   J(phi) = I + (1 - cos a) / a^2 S(phi) + (a - sin a) / a^3 S(phi)^2,  a = |phi|
// (J: the integral of exp(S(w) s) over s in [0, tau], divided by tau). A body turning about a
// line off its centre, as a rod swung about a grasp axis, then keeps the points of that line
// still, where a straight step of the centre, p_n + tau v_n, would pull them off it by
// (tau |w|)^2 / 2 times their distance from the centre (1.4 mm for a rod swinging at 9 rad/s,
// 8 cm off the axis, at 50 Hz). At the next physics step the pose the loops saw and the step's
// differ by the velocity change that step makes times h: continuous up to it.
//
// The fingers' window forces are then measured at poses a mean time `lead` ahead of the step's
// start pose, which the implicit step's finger couplings account for (implicit_stage.cpp).
// Otherwise the fast loops see the physics pose (under integrator = "paper", bit for bit the
// paper).
#pragma once

#include <cstdint>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

struct Pose {
  Mat3 rotation = Mat3::Identity();   // 1: body to world
  Vec3 position{0.0, 0.0, 0.0};       // m: centre of mass, world
  Vec3 velocity{0.0, 0.0, 0.0};       // m/s, world: of the centre of mass (the angular velocity
                                      //    is the body's, constant under the model)
};

// Whether the fast loops see bodies through the local model (Model::local_model, under the
// implicit integrator: the paper's step stays the paper's).
inline bool uses_local_model(const Model& model) {
  return model.local_model && model.integrator == Integrator::kImplicit;
}

// The body's pose at servo tick `tick` as the fast loops see it.
Pose fast_loop_pose(const Model& model, const BodyState& body, std::int64_t tick);

// s: the mean of tau over the servo ticks whose forces one physics window sums, ticks
// t_n + j / servo for j = 1 .. D (D servo ticks a physics period): (D + 1) / (2 servo).
// Zero under the paper's integrator (no local model).
double fast_loop_lead(const Model& model);

}  // namespace graspsim
