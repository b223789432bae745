// Rigid-body integration, the paper's section 3.1: Newton and Newton-Euler accelerations and
// the paper's explicit update of velocity, position, angular velocity and orientation.
#pragma once

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

// The paper's re-orthonormalisation of R = [n o a]: a = a/|a|; n = o x a, n = n/|n|; o = a x n.
void orthonormalize(Mat3& rotation);

// One step of length dt (s) under residual force F (N, world) and torque T (N m, world, about
// the centre of mass):
//   a = F / m                       v = v + a dt        p = p + v dt   (the new v: symplectic)
//   w = w + dw_gyro                 (none for kNeglect, see below)
//   w_dot = R Jp^-1 R^T T           w = w + w_dot dt
//   R = (I + S(w) dt) R_old (kNeglect, the paper's increment) or R = exp(S(w) dt) R_old (the exact
//   turn about w, kExplicit and kImplicit), then orthonormalize(R)
// The gyroscopic term w x J w of the paper's w_dot = J^-1 (T - w x J w), per `gyroscopic`,
// with w_b = R_old^T w (body frame) and dw_gyro = R_old dw_b:
//   kNeglect   dw_b = 0, the paper's approximation for small w or similar principal moments
//              (bit for bit the paper's update; a body spun near its middle axis never flips)
//   kExplicit  dw_b = -dt Jp^-1 (w_b x Jp w_b): with the torque term, Euler's equation by
//              forward Euler, w_b += dt Jp^-1 (T_b - w_b x Jp w_b); adds 1/2 dt^2 g.Jp^-1 g of
//              energy per step (g = w_b x Jp w_b)
//   kImplicit  one Newton step of backward Euler on Jp (w - w_b) + dt w x Jp w = 0 from w_b,
//              dw_b = -Jf^-1 (dt w_b x Jp w_b), Jf = Jp + dt (S(w_b) Jp - S(Jp w_b)) (Catto;
//              Bullet's computeGyroscopicImpulseImplicit_Body): never adds energy while
//              dt |w| <= Jmin / (2 Jmax) (derivation in integrate.cpp)
// kExplicit and kImplicit are first-order accurate for Euler's equations (kNeglect is not
// consistent with them). Where the computed w_b x Jp w_b is exactly zero (w = 0; a spin about a
// principal axis when R^T w rounds exactly onto it) all three give the same angular velocity.
// The paper's orientation increment is not an exact turn about w: with the n-o-a normalisation
// it turns w_b by O(|w|^2 dt^2) per step, which adds or removes energy depending on the order of
// the moments along x, y, z; the gyroscopic options therefore turn exactly about w
// (test_gyroscopic.cpp).
// The paper writes R = R_old (I + S dt); with w in the world frame (as its w_dot is) the
// increment belongs on the left: (I + S(w) dt) R_old = R_old (I + S(R_old^T w) dt).
void integrate_body(const BodyParams& params, Gyroscopic gyroscopic, BodyState& body,
                    const Vec3& force, const Vec3& torque, double dt);

// The implicit integrator's move of one body over dt (s) once its velocities at the end of the
// step are known, given as the force F (N) and torque T (N m, world, about the centre of mass)
// that change them:
//   v1 = v0 + dt F / m          p = p + dt v1
//   w1 = w0 + dt R Jp^-1 R^T T  R = exp(S(w1) dt) R_old, then orthonormalize(R)
// Backward Euler: the pose moves with the velocities the implicit solve found for the end of the
// step, the same displacement h u1 its linearised couplings assumed. (The mean of the start and
// end velocities would move a body under constant force exactly, but it is not the displacement
// the solve assumed: held rods then swing up and handles slip, measured on the library's
// scenarios at 50 Hz.) The gyroscopic change, if any, is in w0 already (gyroscopic_change()).
void move_body(const BodyParams& params, BodyState& body, const Vec3& force, const Vec3& torque, double dt);

// The BDF2 move, the displacement the second-order solve assumed (island_solve.hpp): the body
// takes the end velocities v1, w1 (m/s, rad/s, world) and moves by
//   p = p + dt (v_mean + 2 v1) / 3      R = exp(S(dt (w_mean + 2 w1) / 3)) R_old
// where v_mean, w_mean are the last step's displacement rates. Under constant force this is
// exact: x(t) = a t^2 / 2 is a polynomial of degree two, which BDF2 reproduces.
void move_body_bdf2(BodyState& body, const Vec3& v1, const Vec3& w1, const Vec3& v_mean, const Vec3& w_mean,
                    double dt);

// The implicit integrator's gyroscopic change of the world angular velocity w over dt, taken
// before its solve adds the torques' change: zero for kNeglect; for kExplicit and kImplicit alike
// the torque-free part of Euler's equation, Jp w_b_dot = -w_b x Jp w_b, by the implicit midpoint
// rule on the body-frame angular momentum (integrate.cpp derives it), which conserves the kinetic
// energy and |L| exactly at any spin and rate. The integrator promises not to gain energy at any
// rate; neither first-order scheme keeps that for a body spinning fast on its own (forward Euler
// always gains, the one Newton step only while dt |w| <= Jmin / (2 Jmax)), and move_body turns the
// body exactly about the end w, which leaves R^T w, and so the energy and |L|, as this change made
// them: a free body tumbles at constant energy and |L| up to rounding. The paper's integrator
// (integrate_body) keeps the options' own schemes, as the benchmark measures them.
Vec3 gyroscopic_change(const BodyParams& params, Gyroscopic gyroscopic, const BodyState& body, double dt);

}  // namespace graspsim
