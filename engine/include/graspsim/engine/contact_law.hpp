// The penalty law of a contact point (paper, section 4), written once for the floor and between
// bodies, and what each integrator and check takes from it.
//
// At a point where b meets a (or the floor), with depth d (m, > 0 overlapping), n the unit normal
// along which the contact pushes b, u the velocity of b's material there relative to a's (m/s;
// u_n = n . u > 0 separating, u_t its part across n), and s the friction anchor's stretch (m, across
// n: from b's material point to where it stuck):
//   normal      f_n = k d - c u_n              (unclamped: negative where the law would pull)
//   tangential  f_t = k s - c u_t
// k, c, mu from contact_pair() (materials in series; the implicit integrator's default law where
// none is set, with_default_law). The paper's step clamps it, f_n >= 0 and |f_t| <= mu f_n (+ the
// viscous force while slipping); the implicit step solves it unclamped under an active set that
// clamps (island_solve.hpp). Its spring energy is 1/2 k (d^2 + |s|^2) while d > 0.
#pragma once

#include "graspsim/engine/finger_contact.hpp"
#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"

namespace graspsim {

struct Wrench {
  Vec3 force{0.0, 0.0, 0.0};    // N, world
  Vec3 torque{0.0, 0.0, 0.0};   // N m, world, about the body's centre of mass
};

struct PenaltyForce {
  double normal = 0.0;                 // N: k d - c u_n, unclamped
  Vec3 tangential{0.0, 0.0, 0.0};      // N, world: k s - c u_t
};

inline PenaltyForce penalty_force(const ContactPair& law, double depth, double u_n, const Vec3& stretch,
                                  const Vec3& u_t) {
  return PenaltyForce{law.stiffness * depth - law.damping * u_n, law.stiffness * stretch - law.damping * u_t};
}

// The paper's clamp: the normal force pushes only; the tangential force stays in the friction
// cone of the static (sticking) or kinetic (slipping, plus `viscous`, N) coefficient.
inline void clamp_penalty(const ContactPair& law, bool slipping, double viscous, double& f_n, Vec3& f_t) {
  f_n = std::max(0.0, f_n);
  clamp_to_cone(law.friction(slipping) * f_n + (slipping ? viscous : 0.0), f_t);
}

// The friction anchor of a point whose material point (projected on the contact plane) is
// `material`, pushed with `pushing` (N, >= 0) and sliding over the other side at `u_t` (m/s):
// kept while within the static circle mu f_n / k, moved onto the kinetic circle
// (mu_k f_n + viscous) / k otherwise (stick_slip_step, the fingers' rule). Returns whether it slips.
inline bool move_anchor(const ContactPair& law, double pushing, double viscous, const Vec3& material,
                        const Vec3& u_t, bool slipping, Vec3& anchor) {
  return stick_slip_step(material, law.mu * pushing / law.stiffness,
                         (law.friction(true) * pushing + viscous) / law.stiffness, u_t, slipping, anchor);
}

// J: the energy the point's springs hold.
inline double spring_energy(const ContactPair& law, double depth, const Vec3& stretch) {
  return depth > 0.0 ? 0.5 * law.stiffness * (depth * depth + stretch.squaredNorm()) : 0.0;
}

// A contact's spring (or damper) of coefficient k as a 3 x 3 matrix: isotropic while it holds,
// along the normal only while it slips (the tangential force then sits on the friction cone,
// mu f_n, and no longer follows the displacement).
inline Mat3 contact_matrix(double k, const Vec3& n, bool slipping) {
  return slipping ? Mat3(k * n * n.transpose()) : Mat3(k * Mat3::Identity());
}

// A pair of surfaces that collide: a finite law with some stiffness (both rigid under the paper's
// step, where no default law is filled in, means they pass through each other).
inline bool collides(const ContactPair& p) {
  return std::isfinite(p.stiffness) && std::isfinite(p.damping) && p.stiffness > 0.0;
}

}  // namespace graspsim
