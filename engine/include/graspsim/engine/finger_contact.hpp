// Finger contact: the paper's friction cone algorithm (section 2), one finger at a time, and
// the spring force between the haptic interface point (HIP) and the god-object (GO).
#pragma once

#include <vector>

#include "graspsim/engine/collision.hpp"
#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

// Steps 3 and 4 of the algorithm: the god-object stays put while it lies within the friction
// circle of `radius` about the surface point `sp`; outside it, it moves onto the circle, on the
// line towards `sp`. Compares squared distances, so no root is taken while the finger sticks.
// Returns true when the god-object moved (the finger slipped).
inline bool friction_circle_step(const Vec3& sp, double radius, Vec3& go) {
  const Vec3 d = go - sp;
  const double d2 = d.squaredNorm();
  if (d2 <= radius * radius) return false;
  go = sp + d * (radius / std::sqrt(d2));
  return true;
}

// Coulomb's limit on a tangential force: scaled down onto |f_t| = limit when it is over it.
// Floor points and body points (contact_law.hpp) take their friction force through it.
inline void clamp_to_cone(double limit, Vec3& f_t) {
  const double f_t_norm = f_t.norm();
  if (f_t_norm > limit) f_t *= limit / f_t_norm;
}

// The friction circle with static and kinetic friction, for fingers and floor vertices alike.
// Sticking, the GO moves only when the surface point SP leaves the static circle (then it slips).
// Slipping, the GO follows SP on the kinetic circle, and the contact sticks again only when SP is
// within that circle (to 2e-9 of its squared radius: a GO left on the circle must not be kept
// slipping by rounding) and the relative tangential velocity `v_rel_t` of the finger (or vertex)
// over the surface does not carry SP away from the GO. Deciding by velocity, not by SP's motion
// since the last tick, matters at slow physics rates: between two physics steps a body does not
// move, SP stands still, and a rule on SP alone would re-stick a body sliding through a grip at
// nine haptic ticks in ten. Returns whether the contact is slipping.
bool stick_slip_step(const Vec3& sp, double static_radius, double kinetic_radius,
                     const Vec3& v_rel_t, bool was_slipping, Vec3& go);

// Contact parameters of finger f on body b (or kFloor): the pad and the surface in series.
ContactPair finger_contact_pair(const Model& model, int finger, int body);

// One haptic tick of finger f with the HIP at `hip` (m, world): finds a new contact when the
// finger is free (the feature its path entered), else tracks the surface point over the surface
// (surface_track) and runs the friction cone about it.
// Fills every field of `rec` but `force`, which the servo stage sets (finger_force()).
// `scratch` holds candidate bodies (kept to avoid allocation).
void finger_haptic_step(const Model& model, const State& state, const CollisionWorld& collision,
                        int finger, const Vec3& hip, FingerState& fs, HapticFingerRecord& rec,
                        std::vector<int>& scratch);

// Force on the finger for the newest HIP: k (GO - HIP) + c (v_GO - v_HIP), with k the pad and
// surface in series, c the finger's damping, v_GO the velocity of the body point under the GO
// and v_HIP = (HIP - previous HIP) * servo rate. Zero when free, and zero when it would pull the
// finger into the surface (a contact pushes, never pulls); its tangential part is limited to mu
// times its normal part, both about the stored contact normal (the cone holds at every servo tick). `go_world` receives the GO (m, world).
Vec3 finger_force(const Model& model, const State& state, int finger, const Vec3& hip,
                  Vec3& go_world);

}  // namespace graspsim
