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
//   w_dot = R Jp^-1 R^T T           w = w + w_dot dt
//   R = (I + S(w) dt) R_old, then orthonormalize(R)
// The gyroscopic term w x J w is neglected, as the paper does for small w.
// The paper writes R = R_old (I + S dt); with w in the world frame (as its w_dot is) the
// increment belongs on the left: (I + S(w) dt) R_old = R_old (I + S(R_old^T w) dt).
void integrate_body(const BodyParams& params, BodyState& body, const Vec3& force,
                    const Vec3& torque, double dt);

}  // namespace graspsim
