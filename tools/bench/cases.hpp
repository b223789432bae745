// The hard cases of the work-precision benchmark (tools/bench/README.md), built from engine Models
// only (no Lua, no trace): each runs one configuration (physics rate, gyroscopic option) and
// returns what its error and stability are measured from. Shared by graspsim_bench and tests/bench.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "graspsim/engine/model.hpp"

namespace graspsim::bench {

inline constexpr std::array<Gyroscopic, 3> kIntegrators{Gyroscopic::kNeglect, Gyroscopic::kExplicit,
                                                        Gyroscopic::kImplicit};
const char* integrator_name(Gyroscopic g);   // "neglect", "explicit", "implicit"

// ---- a) spin_flip: torque-free asymmetric body spun near its middle axis (Dzhanibekov) --------
struct SpinFlipSetup {
  Vec3 inertia{1.0, 2.0, 3.0};    // kg m^2: principal moments J1 < J2 < J3 along body x, y, z
  Vec3 spin{0.1, 5.0, 0.1};       // rad/s: initial angular velocity, body = world frame (R = I)
  double duration = 10.0;         // s
};

// The period (s) of Euler's torque-free motion with these moments and initial spin: the body's
// middle axis, projected on the fixed angular momentum, crosses zero every half period.
// T = 4 K(k) / w_p with the Jacobi modulus k and frequency w_p of Landau & Lifshitz, section 37
// (K by the arithmetic-geometric mean). Throws std::invalid_argument unless J1 < J2 < J3 and
// the motion is not exactly on the separatrix.
double intermediate_axis_period(const Vec3& inertia, const Vec3& spin);

Model spin_flip_model(int physics_rate, Gyroscopic g, const SpinFlipSetup& setup = {});

struct SpinFlipResult {
  bool diverged = false;         // the engine flagged the state (non-finite or too fast)
  double energy_drift = 0.0;     // 1: max over the run of |E - E0| / E0
  double energy_gain = 0.0;      // 1: max over the run of (E - E0) / E0 (<= 0: never grew)
  double momentum_drift = 0.0;   // 1: max over the run of |L - L0| / |L0| (world angular momentum)
  int crossings = 0;             // zero crossings of y . L0/|L0| (half flips) in the run
  double period = -1.0;          // s: 2 x mean spacing of those crossings (-1: fewer than 2)
  double period_ref = 0.0;       // s: intermediate_axis_period
};
SpinFlipResult run_spin_flip(int physics_rate, Gyroscopic g, const SpinFlipSetup& setup = {});

// ---- b) gyro_precession: a fast top on a point held by a stiff finger spring ------------------
// A square box (half sizes a, a, h; symmetry axis body z) with its bottom face's centre on a
// point finger (the pivot, l = h below the centre of mass), its axis tilted `tilt` from the
// vertical, spun at `spin` about it, and started in steady precession (the slow root below).
struct PrecessionSetup {
  double mass = 1.0;                  // kg
  Vec3 half_extents{0.05, 0.05, 0.02};   // m: a, a, h
  double spin = 100.0;                // rad/s: w . axis (total angular velocity along the axis)
  double tilt = 0.5235987755982988;   // rad: axis from the vertical (30 degrees)
  double stiffness = 2000.0;          // N/m: finger coupling (the pivot spring)
  double damping = 20.0;              // N s/m: finger damping (kills the spring's own bounce)
  double mu = 1.0;                    // 1: box friction (tan(tilt) = 0.58 needed to stick)
  double duration = 10.0;             // s
  double lever() const { return half_extents.z(); }   // m: l, pivot to centre of mass
};
// Steady precession of a heavy symmetric top about a fixed point (Goldstein 5.7):
//   I1' cos(theta) W^2 - I3 w3 W + m g l = 0,  I1' = I1 + m l^2 (about the pivot), w3 = w . axis;
// the slow root W = (I3 w3 - sqrt(I3^2 w3^2 - 4 I1' cos(theta) m g l)) / (2 I1' cos(theta)),
// which tends to the fast-top rate m g l / (I3 w3) when I3 w3 >> sqrt(I1' m g l). rad/s.
double steady_precession_rate(const PrecessionSetup& setup);
double fast_top_precession_rate(const PrecessionSetup& setup);   // m g l / (I3 w3), rad/s

Model precession_model(int physics_rate, Gyroscopic g, const PrecessionSetup& setup = {});
Vec3 precession_pivot(const PrecessionSetup& setup);   // m, world: where the finger's HIP stays

struct PrecessionResult {
  bool diverged = false;
  bool lost_contact = false;   // the finger let go of the top (it fell)
  double rate = 0.0;           // rad/s: least-squares slope of the axis' azimuth over the run
  double rate_ref = 0.0;       // rad/s: steady_precession_rate
  double max_tilt_change = 0.0;   // rad: largest |tilt - tilt0| (nutation and droop)
};
PrecessionResult run_precession(int physics_rate, Gyroscopic g, const PrecessionSetup& setup = {});

// ---- c) corner_drop: a cube dropped corner first onto a stiff penalty floor --------------------
struct CornerDropSetup {
  double mass = 0.5;        // kg
  double half = 0.05;       // m: half edge
  double drop = 0.01;       // m: lowest corner's height at release
  double tip = 0.08726646259971647;   // rad: off the balanced corner (5 degrees)
  double damping = 1.0;     // N s/m per vertex (floor)
  double mu = 0.6;          // 1
  double duration = 5.0;    // s: long enough for slow rocking instabilities (2 s missed some)
};
// A cube's orientation with its body diagonal vertical, then tipped `tip` rad about (1, 2, 0) so
// that it does not balance on the corner (scenarios/corner_drop.lua, cube_settle.lua).
Quat corner_down(double tip);
// m: the lowest z of a cube's corners (half edge `half`) about its centre, turned by `rotation`.
double lowest_corner(const Mat3& rotation, double half);

Model corner_drop_model(int physics_rate, Gyroscopic g, double stiffness,
                        const CornerDropSetup& setup = {});

// Mechanical energy E = 1/2 m v^2 + 1/2 w_b . J w_b + m g z + sum 1/2 k d^2 over the corners
// below the floor (d their depth); friction springs are left out. A run is unstable when its state
// diverges (the engine's flag: non-finite, faster than 1 km/s or 10^4 rad/s) or when E ever
// exceeds E0 + m g drop: the cube has then more than twice the energy it fell with, which no
// passive contact gives it (a stable run only loses energy, up to the symplectic scheme's bounded
// oscillation about its shadow energy, well inside that bound below the boundary).
struct CornerDropResult {
  bool diverged = false;
  double max_gain = 0.0;        // J: max over the run of E - E0
  double bound = 0.0;           // J: m g drop
  bool stable() const { return !diverged && max_gain <= bound; }
};
CornerDropResult run_corner_drop(int physics_rate, Gyroscopic g, double stiffness,
                                 const CornerDropSetup& setup = {},
                                 std::vector<Vec3>* samples = nullptr);
// samples: the cube's centre (m) at every 1/50 s from t = 0 (the physics rows at those ticks,
// the state at that instant for every rate that is a multiple of 50 Hz), while the run lasts.

// The largest stable floor stiffness (N/m per vertex) at this rate: bisection on log k between
// `low` (must be stable) and `high` (must be unstable; returned as is if it is stable), to a
// relative bracket of 2^(1/8) after at most `iterations` halvings.
double corner_drop_boundary(int physics_rate, Gyroscopic g, const CornerDropSetup& setup = {},
                            double low = 1.0, double high = 1e9, int iterations = 40);

// stability_warnings' estimate (engine/README.md): the rocking mode K/M = 12 k / m is stable
// while h^2 12 k / m < 4 - 2 h 12 c / m, so k < (4 - 24 h c / m) m / (12 h^2). N/m.
double corner_drop_estimate(int physics_rate, const CornerDropSetup& setup = {});

}  // namespace graspsim::bench
