// A contact point as every stage sees it: gathered once a physics step (contact_gather.hpp for the
// floor and between bodies, the implicit stage for fingers), then clamped by the paper's step,
// solved by the implicit step (island_solve.hpp), turned into springs by the stability check.
#pragma once

#include <cstdint>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"

namespace graspsim {

// One contact point as the implicit step sees it: the force it exerts at the start of the step
// and how that force changes as the two bodies move during the step, a spring-damper about the
// present state. With u the velocity of b's material at the point relative to a's (or to the
// world side's velocity), and over the step the point's relative displacement taken as h u1
// (backward Euler):
//   f(u1) = force + (C + lead K) u0 - ((h + lead) K + C) u1,   K = k_n n n^T + k_t (I - n n^T),
// C likewise. `lead` is zero but for a finger seen through the local model (local_model.hpp):
// its force is the mean over a window whose poses ran ahead of the step's start by `lead` on
// average (force - lead K u0 at the start pose), and the next window's will run as far ahead of
// the end pose (force - (h + lead) K u1 there).
// Floor and body points are unilateral with Coulomb friction: after the solve a point whose
// normal force would pull is dropped, and one whose tangential force leaves the cone slips, its
// tangential spring and damper replaced by a sliding force mu f_n (+ viscous) (an active set,
// IslandSolve::solve); its sliding force follows its normal force within the solve.
// Fingers are already held in their cone by the servo stage (mu < 0).
struct Coupling {
  enum class Source : std::uint8_t { kFinger, kFloor, kBody };
  Source source = Source::kFinger;
  int slot = -1;                   // the source's index: finger, floor point, or point of the pair
  int pair = -1;                   // kBody: the pair's index in State::pairs
  int a = -1;                      // body pushed by -f, or -1 for the world (floor, a finger's HIP)
  int b = -1;                      // body pushed by +f
  Vec3 point{0.0, 0.0, 0.0};       // m, world: where the force acts
  Vec3 arm{0.0, 0.0, 0.0};         // m, world: from b's centre of mass to the point
  Vec3 normal{0.0, 0.0, 1.0};      // 1, world, unit: the direction in which the normal force pushes b
  Vec3 world_velocity{0.0, 0.0, 0.0};   // m/s, world: the world side's velocity over the step when
                                        //    a = -1 (a finger's HIP, taken to go on as over the last
                                        //    window; 0 for the floor)
  Vec3 force{0.0, 0.0, 0.0};       // N, world, on b: at the start of the step (floor and body
                                   //    points: the penalty law unclamped, so that it extends linearly)
  double normal_force = 0.0;       // N: floor and body points: the law's normal part, unclamped
  Vec3 tangential_force{0.0, 0.0, 0.0};   // N, world: floor and body points: its tangential part
  double depth = kInfinity;        // m: overlap at the start of the step (< 0: a point the step may
                                   //    reach); infinite for a finger
  double k_n = 0.0, c_n = 0.0;     // N/m, N s/m: along the normal
  double k_t = 0.0, c_t = 0.0;     // N/m, N s/m: across it
  double lead = 0.0;               // s: how far ahead of the step's poses the force is measured
  double mu = -1.0;                // 1: friction limit |f_t| <= mu f_n + viscous; < 0 for none
  double viscous = 0.0;            // N: viscous sliding force c |u_t| at the start (while slipping)
  bool slipping = false;           // floor and body points: the anchor slid at the last step
};

// What the solve decided for a coupling.
enum class CouplingMode : std::uint8_t {
  kHold,    // the whole spring-damper acts (sticking)
  kSlip,    // normal spring-damper and a sliding force on the friction cone
  kOff,     // the point separates: no force
};

// A coupling's response in its mode, G = (h + lead) K + C (N s/m): the force's change per unit of
// relative velocity at the end of the step, kept in the shape that makes its products cheap:
// isotropic, G = g I (a held point whose normal and tangential laws are one); rank one, G = a b^T
// (a sliding point, a = g_n (n + mu t), b = n); or a general 3x3.
struct CouplingResponse {
  enum class Shape : std::uint8_t { kIsotropic, kRankOne, kGeneral };
  Shape shape = Shape::kGeneral;
  double g = 0.0;            // N s/m: kIsotropic
  Vec3 a = Vec3::Zero();     // N s/m: kRankOne, G = a b^T
  Vec3 b = Vec3::Zero();     // 1: kRankOne
  Mat3 full = Mat3::Zero();  // N s/m: kGeneral

  Vec3 times(const Vec3& v) const {   // G v
    if (shape == Shape::kIsotropic) return g * v;
    if (shape == Shape::kRankOne) return b.dot(v) * a;
    return full * v;
  }
};

}  // namespace graspsim
