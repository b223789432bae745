// Accuracy of contact: a 10 cm, 1 kg cube with mu 0.5 on the floor z = 0, resting, on a slope it
// must stick to, on a slope it slides down, and settling after a drop (its cost). Each scene runs
// one physics rate and one contact scheme; a slope is made by tilting gravity, as
// scenarios/incline.lua does. Engine only, shared by graspsim_bench and tests/bench.
#pragma once

#include <array>

#include "graspsim/engine/model.hpp"

namespace graspsim::bench {

// The two ways the cube meets the floor, by Model::integrator:
//   kPaper     the paper's explicit step on the library's soft floor, incline.lua's k = 250 m,
//              c = 2.5 m per vertex (m in kg): the stiffest that is stable at 50 Hz (rocking
//              needs k < (4 - 24 h c / m) m / (12 h^2) = 583 N/m there), so the cube rests
//              m g / (4 k) = 9.8 mm deep at every rate. The default stiffness below is refused
//              by validate() under this scheme.
//   kImplicit  the linearly implicit step with the floor's and the cube's stiffness and damping
//              left unset, so the engine's default rule chooses them from the mass and the
//              physics rate.
inline constexpr std::array<Integrator, 2> kSchemes{Integrator::kPaper, Integrator::kImplicit};
const char* scheme_name(Integrator s);   // "paper", "implicit"

struct ContactSetup {
  double mass = 1.0;           // kg
  double half = 0.05;          // m: half edge; the contact height of the centre, face down
  double mu = 0.5;             // 1: the cube's static and kinetic friction (the floor's is 1)
  double soft_stiffness = 250.0;   // N/m per vertex per kg of cube: kPaper's floor
  double soft_damping = 2.5;       // N s/m per vertex per kg of cube: kPaper's floor
  double duration = 1.0;       // s: rest and slope scenes
  double drop = 0.01;          // m: the settling cube's lowest corner above the floor at release
  double tip = 0.08726646259971647;   // rad: the settling cube off its balanced corner (5 degrees)
  double settle_duration = 2.0;       // s
  bool loops_at_physics_rate = false;  // servo and haptic at the physics rate too (3000 and
                                       //   500 Hz otherwise): the cost of the physics stage alone
};

// The cube face down, its centre at `half` so that its bottom corners touch the floor at depth 0
// (no contact force at t = 0), at rest, under gravity 9.81 m/s^2 tilted by `slope` rad about y:
// g = 9.81 (sin slope, 0, -cos slope), downhill along +x. Loops: servo 3000 Hz, haptic 500 Hz,
// physics `physics_rate` (no fingers: the servo and haptic ticks have nothing to do), or all at
// the physics rate (setup.loops_at_physics_rate).
Model contact_model(int physics_rate, Integrator s, double slope, const ContactSetup& setup = {});

// Every scene reports energy_gain, J: the largest E - E0 over the run, E = 1/2 m v^2 + 1/2 w . J w
// - m g . p (the contact springs' energy, never negative, left out). The cube starts at rest with
// no spring stretched, so a passive step keeps it <= 0 (friction and damping only take energy):
// a gain is energy the scheme made.

// a) At rest face down on the level floor, after setup.duration.
struct RestResult {
  bool diverged = false;
  double energy_gain = 0.0;    // J
  double height_error = 0.0;   // m: |z - half| of the centre (how deep it rests)
  double tilt = 0.0;           // rad: body z from world z
  double speed = 0.0;          // m/s: |v| of the centre at the end
};
RestResult run_rest(int physics_rate, Integrator s, const ContactSetup& setup = {});

// b, c) On a slope, after setup.duration: how far the centre went along the floor.
struct SlopeResult {
  bool diverged = false;
  double energy_gain = 0.0;   // J
  double slide = 0.0;      // m: centre's displacement along x (downhill), floor plane
  double sideways = 0.0;   // m: |displacement along y| (0 by symmetry)
  double sink = 0.0;       // m: half - z, how deep it rests at the end
  double late = 0.0;       // m: distance moved over the floor in the run's second half (a cube
                           //    that holds has stopped: what it moved first is its springs' set)
};
SlopeResult run_slope(int physics_rate, Integrator s, double slope, const ContactSetup& setup = {});

// Coulomb sliding from rest on a slope: x = 1/2 g (sin t - mu cos t) t^2 while tan t > mu, else
// 0 (it sticks). m.
double analytic_slide(double slope, double mu, double time, double g = 9.81);

// d) Dropped corner first from setup.drop (as scenarios/cube_settle.lua, tipped by setup.tip
// so that it does not balance), on the level floor, for setup.settle_duration: it rotates down
// onto an edge, then a face, and rests.
struct SettleResult {
  bool diverged = false;
  double energy_gain = 0.0;     // J
  long long steps = 0;          // physics steps run
  double height_error = 0.0;    // m: |z - half| at the end
  double tilt = 0.0;            // rad: the smallest angle of a body axis from world z at the end
};
SettleResult run_settle(int physics_rate, Integrator s, const ContactSetup& setup = {});

}  // namespace graspsim::bench
