// Hard cases (engine/README.md, "Hard cases"): scenes at the edge of a law or of the explicit
// integration's stability. Each test names its law, derives the value it checks, and sweeps the
// parameter that decides it. The benchmark's hard cases (spin flip, gyroscopic precession, corner
// drop) are in tests/bench; the dead band's own laws are in test_dead_band.cpp. Each case here has
// a scenario (scenarios/dead_band.lua, heavy_hold, stack_mass_ratio, plate_push, incline_threshold,
// rod_swing_fast).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "graspsim/engine/stability.hpp"
#include "tests/engine/harness.hpp"

using namespace graspsim;
using graspsim::test::make_box;
using graspsim::test::make_finger;
using graspsim::test::no_fingers;
using graspsim::test::run;

namespace {

constexpr double kG = 9.81;   // m/s^2

bool finite(const BodyState& b) {
  return b.position.allFinite() && b.velocity.allFinite() && b.angular_velocity.allFinite() &&
         b.rotation.allFinite();
}

// Mechanical energy of every body (translation, rotation, gravity's potential), J. The penalty
// and finger springs store energy >= 0 on top of it, so in a scene without a driver that starts at
// rest with its springs relaxed, no energy gain means this never exceeds its value at t = 0.
double mechanical_energy(const Model& m, const State& s) {
  double e = 0.0;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    const BodyState& b = s.bodies[i];
    const BodyParams& p = m.bodies[i];
    const Vec3 w_body = b.rotation.transpose() * b.angular_velocity;
    e += 0.5 * p.mass * b.velocity.squaredNorm() + 0.5 * w_body.dot(p.inertia.cwiseProduct(w_body)) -
         p.mass * m.gravity.dot(b.position);
  }
  return e;
}

}  // namespace

// =============================================================================================
// 1. The paper's two-point grasp oscillation (section 5) across physics rates.
// =============================================================================================

namespace {

// The rod of test_dead_band.cpp: 20 x 4 x 4 cm, 0.2 kg, pinched across y 8 cm from its centre,
// 8 mm deep, mu = 1, A_crit = 2 A: the restoring torque about the grasp axis is -K sin(theta),
// K = m g d / 2 = 0.07848 N m/rad. The pads' torsional friction c_t makes the turn quasi-static,
// theta' = theta - g sin(theta), g = h K / c_t; c_t is chosen for g = 1.98 at 50 Hz, so the same
// pads give g = 1.98 x 50 / rate at a faster physics rate.
constexpr double kRodMass = 0.2;
const double kRodK = kRodMass * kG * 0.08 * 0.5;    // N m/rad
const double kPads = kRodK / 50.0 / 1.98;           // N m s/rad

Model dead_band_rod(int physics, double dead_band, double start) {
  Model m;
  m.rates.physics = physics;
  m.grasp.torsion = Torsion::kGravityDrop;
  m.grasp.critical_area = 2.0 * M_PI * 0.008 * 0.008;
  m.grasp.torsional_damping = kPads;
  m.grasp.dead_band = dead_band;
  m.bodies.push_back(make_box("rod", kRodMass, Vec3(0.1, 0.02, 0.02), Vec3(0.0, 0.0, 0.3),
                              Material{1.0, kInfinity, kInfinity}));
  m.fingers.push_back(make_finger("thumb", 400.0, 2.0));
  m.fingers.push_back(make_finger("index", 400.0, 2.0));
  const Vec3 pivot(-0.08, 0.0, 0.3);
  const Mat3 turn = Eigen::AngleAxisd(M_PI / 2.0 - start, Vec3::UnitY()).toRotationMatrix();
  m.bodies[0].orientation = Quat(turn);
  m.bodies[0].position = pivot + turn * (Vec3(0.0, 0.0, 0.3) - pivot);
  return m;
}

struct TorsionRun {
  std::vector<double> angle;   // rad from hanging, at each physics step
  std::vector<double> turn;    // rad turned by the rule at that step
  bool held = true;
};

TorsionRun torsion_run(const Model& m, double seconds) {
  Simulation sim(m);
  TorsionRun r;
  run(sim, static_cast<std::int64_t>(3000 * seconds),
      [](std::size_t f, double) { return Vec3(-0.08, f == 0 ? -0.012 : 0.012, 0.3); },
      [&](const TickRecord& t) {
        if (!t.physics_ran) return;
        const Vec3 x = Mat3(t.physics[0].orientation).col(0);
        r.angle.push_back(std::atan2(x.x(), -x.z()));
        r.turn.push_back(t.physics[0].twist);
        r.held = r.held && t.physics[0].grasp_area > 0.0;
      });
  return r;
}

}  // namespace

// The oscillation is the slow update's, and faster physics removes it. Map theta' = theta -
// g sin(theta) from theta0 = 0.1 rad, g = 1.98 x 50 / rate:
//  - sign reversals: every step for g > 1 (50 Hz: 1.98), none for g < 1 (100 Hz and faster: the
//    step never passes the minimum, since theta - g sin(theta) >= theta (1 - g) > 0);
//  - contraction per step |theta'| / |theta| = |1 - g sinc(theta)| <= q = max(|1 - g|,
//    |1 - g sinc(theta0)|), so after N steps |theta_N| <= theta0 q^N (amplitude bound, checked at
//    N = 25, and from below by theta0 q_min^N with q_min the other end of the range);
//  - with the band T_crit = 2 mN m, the rod stops for good within N_stop = ceil(ln(x_c / theta0)
//    / ln q) + 1 steps, x_c = asin(T_crit / K), at a final angle in [|g sin(x_c) - x_c|, x_c]:
//    it was outside the band one step before and theta - g sin(theta) is monotone there.
// Measured (step, bound): 50 Hz (65, 69) = 1.3 s, 0.0250 rad; 100 Hz (1, 2), 0.0012 rad; 250 Hz
// (3, 4); 500 Hz (7, 8); 1000 Hz (14, 15); 3000 Hz (41, 42) = 0.014 s, 0.0253 rad: faster physics
// stops within a few hundredths of a second, at the band's edge (x_c = 0.0255 rad). The bounds are
// the map's own, exact up to rounding in the rotation products (1e-12 rad, test_dead_band.cpp).
TEST_CASE("the grasp oscillation at 50 Hz is gone at faster physics and the band stops both",
          "[hard][dead_band][law]") {
  const double theta0 = 0.1, t_crit = 0.002;
  const double x_c = std::asin(t_crit / kRodK);
  for (int rate : {50, 100, 250, 500, 1000, 3000}) {
    const double g = 1.98 * 50.0 / rate;
    const double sinc0 = std::sin(theta0) / theta0;
    const double q = std::max(std::abs(1.0 - g), std::abs(1.0 - g * sinc0));
    const double q_min = std::min(std::abs(1.0 - g), std::abs(1.0 - g * sinc0));
    INFO("physics " << rate << " Hz, gain " << g);

    const TorsionRun free = torsion_run(dead_band_rod(rate, 0.0, theta0), 1.0);
    REQUIRE(free.angle.size() == static_cast<std::size_t>(rate));
    CHECK(free.held);
    int reversals = 0;
    for (std::size_t n = 1; n < free.turn.size(); ++n) reversals += free.turn[n] * free.turn[n - 1] < 0.0;
    if (g > 1.0) {
      CHECK(reversals == rate - 1);
    } else {
      CHECK(reversals == 0);
    }
    const int n = 25;
    const double a_n = std::abs(free.angle[n]);
    if (theta0 * std::pow(q_min, n) > 1e-12) {   // not yet at rounding level
      CHECK(a_n <= theta0 * std::pow(q, n) * (1.0 + 1e-9));
      CHECK(a_n >= theta0 * std::pow(q_min, n) * (1.0 - 1e-9));
    }

    const TorsionRun banded = torsion_run(dead_band_rod(rate, t_crit, theta0), 2.0);
    CHECK(banded.held);
    std::size_t stop = banded.turn.size();
    while (stop > 0 && banded.turn[stop - 1] == 0.0) --stop;
    const auto bound = static_cast<std::size_t>(std::ceil(std::log(x_c / theta0) / std::log(q))) + 1;
    const double final_angle = std::abs(banded.angle.back());
    INFO("stopped at step " << stop << " (bound " << bound << "), " << final_angle << " rad from hanging");
    CHECK(stop <= bound);
    CHECK(stop < banded.turn.size());
    CHECK(final_angle <= x_c);
    CHECK(final_angle >= std::abs(g * std::sin(x_c) - x_c) * (1.0 - 1e-9));
  }
}

// =============================================================================================
// 3. A heavy box held just above the slip threshold, and just below it.
// =============================================================================================

namespace {

struct HoldOutcome {
  double rise;          // m: how far the box's centre rose
  double slip;          // m: god-object slip of both fingers from 0.2 s on (the pinch has formed)
  double hold_speed;    // m/s: box speed at the end
  bool finite = true;
};

constexpr double kHeavy = 5.0;            // kg: a 10 cm cube
constexpr double kHoldK = 5000.0;         // N/m per finger
constexpr double kHoldFloorK = 1250.0;    // N/m per vertex: h^2 12 k / m = 1.2 at 50 Hz

// The box rests on a soft floor; two fingers (k each, 20 N s/m) pinch it across x, each
// `margin` x m g / (2 mu k) deep, from 0.2 s rise `lift` m at `speed` m/s, and hold for 3 s.
HoldOutcome heavy_hold(int physics, double margin, double mu, double speed, double lift) {
  const Vec3 h(0.05, 0.05, 0.05);
  Model m;
  m.rates.physics = physics;
  m.floor.enabled = true;
  m.floor.material = Material{1.0, kHoldFloorK, kHoldFloorK / 100.0};
  const double sag = kHeavy * kG / (4.0 * kHoldFloorK);
  const double z0 = h.z() - sag;
  m.bodies.push_back(make_box("box", kHeavy, h, Vec3(0.0, 0.0, z0), Material{mu, kInfinity, kInfinity}));
  m.fingers.push_back(make_finger("thumb", kHoldK, 20.0));
  m.fingers.push_back(make_finger("index", kHoldK, 20.0));
  const double d = margin * kHeavy * kG / (2.0 * mu * kHoldK);
  const double t0 = 0.2, t_end = t0 + lift / speed + 3.0;
  Simulation sim(m);
  HoldOutcome out{0.0, 0.0, 0.0};
  run(sim, static_cast<std::int64_t>(3000 * t_end),
      [&](std::size_t i, double t) {
        const double z = z0 + std::clamp(speed * (t - t0), 0.0, lift);
        return Vec3(i == 0 ? -(h.x() - d) : (h.x() - d), 0.0, z);
      },
      [&](const TickRecord& r) {
        if (r.haptic_ran && sim.time() > t0) out.slip += r.haptic[0].slip + r.haptic[1].slip;
      });
  out.rise = sim.state().bodies[0].position.z() - z0;
  out.hold_speed = sim.state().bodies[0].velocity.norm();
  out.finite = finite(sim.state().bodies[0]);
  return out;
}

}  // namespace

// Coulomb's law in the grip: two fingers pressed d deep carry at most 2 mu k d, so a box of weight
// m g is lifted when 2 mu k d > m g (margin > 1) and stays on the floor when it is less. The lift
// is slow (2 mm/s) so that the load moves from the floor to the fingers quasi-statically:
//  - held (margin 1.015 to 1.2, above the 1.1% the lift-off needs, below): no god-object moves
//    once the pinch has formed (slip exactly 0),
//    and the box ends hanging from the fingers at lift - m g / (2 k) above its start (the springs'
//    stretch 4.9 mm), to 1e-6 m (its residual ringing, damping ratio 0.09 at 45 rad/s, has decayed
//    by e^-12 in the 3 s hold);
//  - too weak (margin 0.8 to 0.99): the fingers slide up the faces, each carrying its kinetic
//    friction mu k d (mu_k = mu here), so the floor carries the rest and the box rises only by the
//    floor springs' relief 2 mu k d / (4 k_floor), to 1e-6 m, while the god-objects slip the full
//    lift (more than 90% of 2 x 1 cm).
// Why slowly: when the box leaves the floor it moves at v 2k / (2k + 4 k_floor) = v / 2 and must
// take the fingers' v: the step dv = v / 2 rings the grip spring (w = sqrt(2k / m) = 45 rad/s)
// by dv / w over its stretch s = m g / (2k), i.e. a margin needed of 1 + v / (2 w s): 1.1% at
// 2 mm/s, 4.6% at 2 cm/s (next test). 50 Hz and 500 Hz physics; the law does not depend on it.
TEST_CASE("a heavy box held just above the slip threshold is lifted, just below it slips",
          "[hard][grasp][friction][law]") {
  const double mu = 0.5, speed = 0.002, lift = 0.03;
  for (int rate : {50, 500}) {
    for (double margin : {1.2, 1.05, 1.02, 1.015}) {
      const HoldOutcome o = heavy_hold(rate, margin, mu, speed, lift);
      INFO("physics " << rate << " Hz, margin " << margin << ": rose " << o.rise << " m, slip " << o.slip << " m");
      CHECK(o.finite);
      CHECK(o.slip == 0.0);
      CHECK(o.rise == Approx(lift - kHeavy * kG / (2.0 * kHoldK)).margin(1e-6));
      CHECK(o.hold_speed < 1e-4);
    }
    for (double margin : {0.99, 0.98, 0.95, 0.8}) {
      const HoldOutcome o = heavy_hold(rate, margin, mu, speed, lift);
      const double d = margin * kHeavy * kG / (2.0 * mu * kHoldK);
      INFO("physics " << rate << " Hz, margin " << margin << ": rose " << o.rise << " m, slip " << o.slip << " m");
      CHECK(o.finite);
      CHECK(o.rise == Approx(2.0 * mu * kHoldK * d / (4.0 * kHoldFloorK)).margin(1e-6));
      CHECK(o.slip == Approx(2.0 * (lift - mu * d - o.rise)).epsilon(1e-3));
    }
  }
}

// The dynamic margin of the previous test: lifted at 2 cm/s, the lift-off step dv = v / 2 rings
// the grip by dv / w = 0.22 mm over its 4.9 mm stretch, so the friction circle must exceed the
// static load by about 4.6% (less the damping's share: ratio 0.09) or the fingers slip at
// lift-off. Margin 1.1 lifts without a slip; 1.02 slips at lift-off (by more than 0.1 mm) and
// then holds: it still ends hanging at rest, lower than the full lift by what slipped.
TEST_CASE("a fast lift needs the margin of the grip's ringing at lift-off", "[hard][grasp][friction][law]") {
  const double mu = 0.5, speed = 0.02, lift = 0.05;
  for (int rate : {50, 500}) {
    const HoldOutcome safe = heavy_hold(rate, 1.1, mu, speed, lift);
    const HoldOutcome tight = heavy_hold(rate, 1.02, mu, speed, lift);
    INFO("physics " << rate << " Hz: margin 1.1 slip " << safe.slip << " m, margin 1.02 slip " << tight.slip
                    << " m, rose " << tight.rise << " m");
    CHECK(safe.slip == 0.0);
    CHECK(safe.rise == Approx(lift - kHeavy * kG / (2.0 * kHoldK)).margin(1e-6));
    CHECK(tight.slip > 1e-4);
    CHECK(tight.rise < lift - kHeavy * kG / (2.0 * kHoldK) - 1e-4);
    CHECK(tight.rise > 0.5 * lift);
    CHECK(tight.hold_speed < 1e-2);
  }
}

// =============================================================================================
// 4. A stack with a 100:1 mass ratio, light on heavy and heavy on light.
// =============================================================================================

namespace {

struct StackOutcome {
  double top_depth = 0.0;      // m: deepest corner of the top box below the bottom's top face
  double floor_depth = 0.0;    // m: deepest corner of the bottom box below the floor
  double energy_gain = 0.0;    // J: largest E(t) - E(0), E the bodies' mechanical energy
  double jitter_early = 0.0;   // m/s: largest body speed between 1 and 2 s
  double jitter_late = 0.0;    // m/s: largest body speed in the last second
  bool finite = true;
};

// A top box (8 x 8 x 2 cm, contact k, c per point) on a bottom box (16 x 16 x 4 cm) on the
// floor (k_floor, c_floor per vertex), both let go at rest `gap` m above their contacts.
Model stack_model(int physics, double bottom, double top, double k, double c, double k_floor,
                  double c_floor, double gap) {
  Model m;
  m.rates.physics = physics;
  m.floor.enabled = true;
  m.floor.material = Material{0.8, k_floor, c_floor};
  const Vec3 hb(0.08, 0.08, 0.02), ht(0.04, 0.04, 0.01);
  m.bodies.push_back(make_box("bottom", bottom, hb, Vec3(0.0, 0.0, hb.z() + gap), Material{0.8, kInfinity, kInfinity}));
  m.bodies.push_back(make_box("top", top, ht, Vec3(0.0, 0.0, 2.0 * hb.z() + ht.z() + 2.0 * gap), Material{0.5, k, c}));
  // A nudge: a stack started exactly symmetric never excites its rocking modes, stable or not.
  m.bodies[0].angular_velocity = Vec3(0.01, 0.007, 0.0);
  return m;
}

StackOutcome stack_drop(const Model& m, double seconds) {
  const Vec3 hb = m.bodies[0].shape.half_extents, ht = m.bodies[1].shape.half_extents;
  Simulation sim(m);
  const double e0 = mechanical_energy(m, sim.state());
  StackOutcome out;
  run(sim, static_cast<std::int64_t>(3000 * seconds), no_fingers, [&](const TickRecord& r) {
    if (!r.physics_ran) return;
    const State& s = sim.state();
    const BodyState& b = s.bodies[0];
    const BodyState& t = s.bodies[1];
    for (int i = 0; i < 4; ++i) {
      const double sx = i & 1 ? 1.0 : -1.0, sy = i & 2 ? 1.0 : -1.0;
      const Vec3 in_bottom = b.rotation.transpose() * (t.position + t.rotation * Vec3(sx * ht.x(), sy * ht.y(), -ht.z()) - b.position);
      out.top_depth = std::max(out.top_depth, hb.z() - in_bottom.z());
      out.floor_depth = std::max(out.floor_depth, -(b.position + b.rotation * Vec3(sx * hb.x(), sy * hb.y(), -hb.z())).z());
    }
    out.energy_gain = std::max(out.energy_gain, mechanical_energy(m, s) - e0);
    // Speed of the fastest material point: the centre's speed plus |w| times the half diagonal.
    const double v = std::max(b.velocity.norm() + b.angular_velocity.norm() * hb.norm(),
                              t.velocity.norm() + t.angular_velocity.norm() * ht.norm());
    const double time = sim.time();
    if (time > 1.0 && time <= 2.0) out.jitter_early = std::max(out.jitter_early, v);
    if (time > seconds - 1.0) out.jitter_late = std::max(out.jitter_late, v);
    out.finite = out.finite && finite(b) && finite(t);
  });
  return out;
}

// The largest spectral radius the coupled-mode check (stability.hpp) finds over a drop lasting
// `seconds`, analysing each contact set the stack reaches (not the model alone).
double worst_radius(const Model& m, double seconds) {
  Simulation sim(m);
  StabilityMonitor monitor(m);
  double worst = 0.0;
  run(sim, static_cast<std::int64_t>(3000 * seconds), no_fingers, [&](const TickRecord& r) {
    if (!r.physics_ran) return;
    monitor.update(sim.state());
    const StabilityReport& report = monitor.report();
    if (report.worst >= 0) worst = std::max(worst, report.groups[report.worst].radius);
  });
  return worst;
}

bool flags_pair(const Model& m) {
  for (const std::string& w : stability_warnings(m)) {
    if (w.find("'bottom' and 'top'") != std::string::npos) return true;
  }
  return false;
}

}  // namespace

// Penalty contact at a 100:1 mass ratio. Both boxes start at rest 1 mm above their contacts, the
// bottom one nudged (0.01 rad/s): a stack started exactly symmetric never excites its rocking
// modes, stable or not, and would hide an unstable one.
//  - Depth: each contact point carries at most the whole weight above it, so no corner sinks
//    deeper than the penalty depth m g / k (m the mass above that contact, k per point). The bound
//    is checked, not derived for the drop; measured: light on heavy 0.60 (top) and 0.42 (floor) of
//    it, heavy on light 0.65 and 0.65.
//  - Energy: no driver, started at rest with relaxed springs, so the bodies' mechanical energy
//    never exceeds its start (springs only store energy >= 0); checked to 1e-9 J (rounding of a
//    ~0.3 J potential). Weak for the light body: its energy is 1% of the scene's.
//  - Jitter: the fastest material point's speed (centre speed + |w| x half diagonal) in the last
//    second is below 1e-4 m/s and below its largest between 1 and 2 s (no growth). Measured
//    2e-3 -> 1e-7 m/s light on heavy (4 s), 3.4e-2 -> 1.2e-5 m/s heavy on light (6 s).
// Light on heavy (10 g on 1 kg, k = 40 N/m, c = 0.05 N s/m per point, floor 250 N/m): the light
// box's rocking h^2 12 k / m_r = 48 / rate^2 x 1e3 is stable from about 110 Hz; tested at 250,
// 1000 and 3000 Hz, and flagged by stability_warnings() and by the coupled-mode check
// (StabilityMonitor over the drop: radius above 1) at 50 and 100 Hz, by neither at the others.
// Heavy on light (1 kg on 10 g, k = 2500 N/m per point and per floor vertex, c = 2 N s/m): the
// light box is squeezed between two stiff springs, h^2 12 k / m = 3e6 / rate^2: stable at 3000 Hz
// only. Both checks flag 250, 500 and 1000 Hz (measured at 1000 Hz with c = 4: depth 142 m,
// energy +26 J), not 3000 Hz. With c = 4 at 3000 Hz the light box rocks for ever (0.9 m/s at its
// corners, a limit cycle): its rocking feels both of its contacts, the floor's and the heavy
// box's, h C / I = 1.9 with both, 0.94 with each alone. stability_warnings() checks each contact
// alone and misses it; the coupled-mode check assembles both on the light box and flags it
// (radius 1.32).
TEST_CASE("a 100:1 stack settles without sinking past m g / k or gaining energy", "[hard][stack][law]") {
  const double g = kG;
  SECTION("light on heavy") {
    for (int rate : {250, 1000, 3000}) {
      const Model m = stack_model(rate, 1.0, 0.01, 40.0, 0.05, 250.0, 2.5, 0.001);
      const StackOutcome o = stack_drop(m, 4.0);
      INFO("physics " << rate << " Hz: top " << o.top_depth << " m, floor " << o.floor_depth << " m, gain "
                      << o.energy_gain << " J, jitter " << o.jitter_early << " -> " << o.jitter_late << " m/s");
      CHECK(o.finite);
      CHECK(o.top_depth <= 0.01 * g / 40.0);
      CHECK(o.floor_depth <= 1.01 * g / 250.0);
      CHECK(o.energy_gain <= 1e-9);
      CHECK(o.jitter_late < 1e-4);
      CHECK(o.jitter_late < o.jitter_early);
      CHECK_FALSE(flags_pair(m));
      CHECK(worst_radius(m, 2.0) <= kUnstableRadius);
    }
    for (int rate : {50, 100}) {
      const Model m = stack_model(rate, 1.0, 0.01, 40.0, 0.05, 250.0, 2.5, 0.001);
      CHECK(flags_pair(m));
      CHECK(worst_radius(m, 2.0) > kUnstableRadius);
    }
  }
  SECTION("heavy on light") {
    const Model m = stack_model(3000, 0.01, 1.0, 2500.0, 2.0, 2500.0, 2.0, 0.001);
    const StackOutcome o = stack_drop(m, 6.0);
    INFO("top " << o.top_depth << " m, floor " << o.floor_depth << " m, gain " << o.energy_gain
                << " J, jitter " << o.jitter_early << " -> " << o.jitter_late << " m/s");
    CHECK(o.finite);
    CHECK(o.top_depth <= 1.0 * g / 2500.0);
    CHECK(o.floor_depth <= 1.01 * g / 2500.0);
    CHECK(o.energy_gain <= 1e-9);
    CHECK(o.jitter_late < 1e-4);
    CHECK(o.jitter_late < o.jitter_early);
    CHECK_FALSE(flags_pair(m));
    CHECK(worst_radius(m, 2.0) <= kUnstableRadius);
    for (int rate : {250, 500, 1000}) {
      const Model fast = stack_model(rate, 0.01, 1.0, 2500.0, 2.0, 2500.0, 2.0, 0.001);
      CHECK(flags_pair(fast));
      CHECK(worst_radius(fast, 2.0) > kUnstableRadius);
    }
  }
  SECTION("heavy on light, damped beyond the light box's rocking: a lasting cycle, flagged") {
    const Model m = stack_model(3000, 0.01, 1.0, 2500.0, 4.0, 2500.0, 4.0, 0.001);
    const StackOutcome o = stack_drop(m, 4.0);
    INFO("jitter " << o.jitter_early << " -> " << o.jitter_late << " m/s");
    CHECK(o.finite);
    CHECK(o.jitter_late > 0.1);
    CHECK_FALSE(flags_pair(m));   // the estimate, one contact at a time, misses the sandwiched body
    CHECK(worst_radius(m, 2.0) > kUnstableRadius);   // the coupled-mode check sees it
  }
}

// =============================================================================================
// 5. A thin plate pushed hard by a finger.
// =============================================================================================

namespace {

struct PlateOutcome {
  double lowest_hip = 1.0;        // m: the HIP's lowest height
  double worst_side = 1.0;        // m: lowest height of the GO over the plate's top face (its frame)
  bool on_plate = true;           // once in contact, the finger touched the plate at every haptic tick
  bool touched = false;
  double sink = 0.0;              // m: the plate's bottom face below the floor at the end
  double speed = 0.0;             // m/s: plate speed at the end
  bool finite = true;
};

constexpr double kPlateMass = 0.15;   // kg: 10 x 10 x 0.2 cm of steel
const Vec3 kPlateHalf(0.05, 0.05, 0.001);

// The plate lies on a floor of k_floor per vertex (c = k_floor / 1000); a finger (k, 5 N s/m)
// comes down on its centre from 1 cm above its top at `speed` m/s, to the height `hip_z` (below
// the floor), and holds there. (Off centre the plate tilts and its corner dips further: the
// balance below holds for a central push, which keeps the plate level by symmetry.)
PlateOutcome plate_push(int physics, double speed, double hip_z, double k, double k_floor) {
  Model m;
  m.rates.physics = physics;
  m.floor.enabled = true;
  m.floor.material = Material{0.8, k_floor, k_floor / 1000.0};
  const double sag = kPlateMass * kG / (4.0 * k_floor);
  m.bodies.push_back(make_box("plate", kPlateMass, kPlateHalf, Vec3(0.0, 0.0, kPlateHalf.z() - sag),
                              Material{0.8, kInfinity, kInfinity}));
  m.fingers.push_back(make_finger("finger", k, 5.0));
  const double z_start = 2.0 * kPlateHalf.z() + 0.01;
  Simulation sim(m);
  PlateOutcome out;
  run(sim, 3000 * 3,
      [&](std::size_t, double t) { return Vec3(0.0, 0.0, std::max(hip_z, z_start - speed * t)); },
      [&](const TickRecord& r) {
        out.lowest_hip = std::min(out.lowest_hip, r.servo[0].hip.z());
        if (!r.haptic_ran) return;
        const HapticFingerRecord& f = r.haptic[0];
        if (f.body != kNoBody) out.touched = true;
        if (!out.touched) return;
        out.on_plate = out.on_plate && f.body == 0;
        // The GO as the engine keeps it, in the plate's frame (the record's is in world, before
        // the physics step of the same tick moves the plate).
        const Vec3& go = sim.state().fingers[0].god_object;
        out.worst_side = std::min(out.worst_side, go.z() - kPlateHalf.z());
      });
  const BodyState& p = sim.state().bodies[0];
  out.sink = kPlateHalf.z() - p.position.z();
  out.speed = p.velocity.norm();
  out.finite = finite(p);
  return out;
}

}  // namespace

// No tunnelling: a finger that enters the top face of a 2 mm plate keeps its god-object on that
// face however far the HIP goes, even through the plate and the floor under it within one haptic
// tick (at 5 m/s it moves 1 cm, five plate thicknesses, per 2 ms). In the plate's frame the GO
// stays on the top face (z = +1 mm, to 1e-12 m: it is projected there), the finger never touches
// the floor instead, and the plate ends at the static balance of the finger's spring on its top
// face and the floor's springs under it. Sunk s deep (2 t the thickness), its four bottom vertices
// push 4 k_f s, and once s > 2 t its four top vertices are under the floor too and add
// 4 k_f (s - 2 t) (the penalty floor acts on every vertex):
//   4 k_f (s + max(0, s - 2 t)) = m g + k (2 t - s - z_hip)
//   s = (m g + k (2 t - z_hip)) / (4 k_f + k)                    if that is <= 2 t,
//   s = (m g + k (2 t - z_hip) + 8 k_f t) / (8 k_f + k)           otherwise,
// to 1e-6 m after 3 s (the slowest mode, the plate on the finger and floor springs, 235 rad/s, is
// damped with ratio ~0.1). Swept over the push (the HIP held 1 cm to 20 cm below the floor: 4 to
// 60 N, the plate pressed 0.61, 2.03 and 4.79 mm into the floor, its top below the floor's
// surface from 5 cm on) and the finger's speed (0.1 to 5 m/s).
// Physics at 500 and 3000 Hz, not 50: the floor must hold the plate above its own thickness,
// m g / (4 k_f) < 2 mm, so k_f > 184 N/m, while the plate's rocking at 50 Hz needs
// h^2 12 k_f / m < 4, k_f < 125 N/m. At the paper's rate a 2 mm, 0.15 kg plate sinks below the floor
// under its own weight (scenarios/plate_push.lua states it).
TEST_CASE("a finger pushed hard through a thin plate stays on its top face", "[hard][finger_contact][law]") {
  const double k = 300.0, k_floor = 2000.0;
  for (int rate : {500, 3000}) {
    for (double speed : {0.1, 1.0, 5.0}) {
      for (double hip_z : {-0.01, -0.05, -0.2}) {
        const PlateOutcome o = plate_push(rate, speed, hip_z, k, k_floor);
        const double t2 = 2.0 * kPlateHalf.z();
        double expected = (kPlateMass * kG + k * (t2 - hip_z)) / (4.0 * k_floor + k);
        if (expected > t2) expected = (kPlateMass * kG + k * (t2 - hip_z) + 4.0 * k_floor * t2) / (8.0 * k_floor + k);
        INFO("physics " << rate << " Hz, " << speed << " m/s to " << hip_z << " m: GO " << o.worst_side
                        << " m over the top face, sink " << o.sink << " m (expected " << expected << ")");
        CHECK(o.finite);
        CHECK(o.touched);
        CHECK(o.on_plate);
        CHECK(o.lowest_hip == Approx(hip_z).margin(1e-12));
        CHECK(std::abs(o.worst_side) < 1e-12);
        CHECK(o.sink == Approx(expected).margin(1e-6));
        CHECK(o.speed < 1e-5);
      }
    }
  }
}

// =============================================================================================
// 6. A box on an incline just below and just above tan(theta) = mu.
// =============================================================================================

namespace {

struct InclineOutcome {
  double base_moved = 0.0;   // m: downhill displacement of the base's centre by 2 s
  double moved_late = 0.0;   // m: displacement between 2 s and 3 s
  double accel = 0.0;        // m/s^2: velocity change between 2 s and 3 s over 1 s
  double speed = 0.0;        // m/s at 3 s
};

constexpr double kInclineMass = 0.4;
const Vec3 kInclineHalf(0.06, 0.06, 0.02);   // a flat box (like a book): it slides, it does not tip
constexpr double kInclineK = 100.0;          // N/m per vertex

// The incline is gravity tilted by theta about y (downhill +x); mu_s = mu_k = mu on the floor
// (k = 100 N/m, damping c per vertex). The box starts at rest at its normal penalty depth.
InclineOutcome incline(int physics, double mu, double tan_theta, double c) {
  const double theta = std::atan(tan_theta);
  Model m;
  m.rates.physics = physics;
  m.gravity = Vec3(kG * std::sin(theta), 0.0, -kG * std::cos(theta));
  m.floor.enabled = true;
  m.floor.material = Material{mu, kInclineK, c};
  const double sag = kInclineMass * kG * std::cos(theta) / (4.0 * kInclineK);
  m.bodies.push_back(make_box("box", kInclineMass, kInclineHalf, Vec3(0.0, 0.0, kInclineHalf.z() - sag),
                              Material{mu, kInfinity, kInfinity}));
  Simulation sim(m);
  run(sim, 3000 * 2, no_fingers);
  InclineOutcome out;
  const auto base = [&] {
    const BodyState& b = sim.state().bodies[0];
    return Vec3(b.position + b.rotation * Vec3(0.0, 0.0, -kInclineHalf.z())).x();
  };
  out.base_moved = base();
  const double v2 = sim.state().bodies[0].velocity.x();
  run(sim, 3000, no_fingers);
  out.moved_late = base() - out.base_moved;
  out.accel = sim.state().bodies[0].velocity.x() - v2;
  out.speed = sim.state().bodies[0].velocity.norm();
  return out;
}

}  // namespace

// Coulomb's threshold on an incline, swept to within 1% of it. The load comes on as a step at
// t = 0 (gravity is constant in the Model), and while the anchors' springs and dampers take it up
// the floor's friction force overshoots the load by the box's peak deceleration: a lightly damped
// spring swings to twice its static stretch (past the friction circle for any tan(theta) > mu / 2:
// measured at 50 Hz with c = 1 N s/m, the box slides 5.5 cm at 0.98 mu before it catches, and at
// 0.99 mu is still sliding after 3 s; engine/README.md, Limits). An overdamped anchor overshoots by
// about m K / C^2 (K = 4 k, C = 4 c the totals): with c = 20 N s/m per vertex 2.5%, beyond the
// paper's 50 Hz (the rocking mode's 2 h 12 c / m = 24 > 4) and stable at 500 and 3000 Hz.
//  - Below (tan(theta) = 0.9 to 0.99 mu): the box stops and stays, less than 1e-6 m over the last
//    second. Up to 0.98 mu (inside the 2.5% overshoot) it moves only by its anchors' stretch: the
//    friction at the base, h_z below the centre, loads the downhill vertices with N_d = m g cos / 4
//    + F h_z / (4 h_x), F = m g sin; the uphill ones may slip (they carry less), the downhill ones
//    hold while F < mu m g cos, and their stretch is at most mu N_d / k: the base centre moves by
//    less than 3.1 mm (mu = 0.3) or 6.1 mm (0.6). At 0.99 mu the overshoot breaks the grip of
//    every vertex and its base slides 4.1 mm (0.3) or 8.5 mm (0.6) before it catches (measured).
//  - Above (1.01 to 1.1 mu): every vertex is on its circle, so the floor's tangential force is
//    exactly mu times its normal force and a = g (sin - mu cos), from 0.028 m/s^2 at 1.01 mu
//    (mu 0.3). Measured over 2 to 3 s, within 1e-3 relative (the box's residual rocking), here
//    and with the light c = 1 N s/m at the paper's 50 Hz.
TEST_CASE("a box on an incline sticks just below tan(theta) = mu and slides just above it",
          "[hard][floor][friction][law]") {
  for (int rate : {50, 500, 3000}) {
    const double c = rate == 50 ? 1.0 : 20.0;   // N s/m per vertex
    for (double mu : {0.3, 0.6}) {
      if (rate != 50) {
        for (double factor : {0.9, 0.95, 0.98, 0.99}) {
          const double theta = std::atan(factor * mu);
          const InclineOutcome o = incline(rate, mu, factor * mu, c);
          const double n_down = kInclineMass * kG * std::cos(theta) / 4.0 +
                                kInclineMass * kG * std::sin(theta) * kInclineHalf.z() / (4.0 * kInclineHalf.x());
          INFO("physics " << rate << " Hz, mu " << mu << ", tan(theta) = " << factor << " mu: base moved "
                          << o.base_moved << " m (bound " << mu * n_down / kInclineK << " m), then " << o.moved_late << " m");
          CHECK(o.base_moved >= 0.0);
          if (factor <= 0.98) CHECK(o.base_moved <= mu * n_down / kInclineK);
          CHECK(std::abs(o.moved_late) < 1e-6);
          CHECK(o.speed < 1e-6);
        }
      }
      for (double factor : {1.01, 1.02, 1.05, 1.1}) {
        const double theta = std::atan(factor * mu);
        const InclineOutcome o = incline(rate, mu, factor * mu, c);
        const double a = kG * (std::sin(theta) - mu * std::cos(theta));
        INFO("physics " << rate << " Hz, mu " << mu << ", tan(theta) = " << factor << " mu: a " << o.accel
                        << " m/s^2, expected " << a);
        CHECK(o.accel == Approx(a).epsilon(1e-3));
      }
    }
  }
}

// =============================================================================================
// 2. A long rod gripped at one end and swung fast.
// =============================================================================================

namespace {

struct SwingOutcome {
  double widest = 0.0;        // rad: largest tilt of the rod from vertical
  double slip = 0.0;          // m: god-object slip of both fingers from 0.2 s on (the grip formed)
  bool held = true;           // both fingers on the rod at every haptic tick
  double worst_ratio = 0.0;   // 1: largest |f_t| / (mu f_n) of a finger's servo force
  double e_stop = 0.0;        // J: swing energy when the hand stops
  double e_after = 0.0;       // J: largest swing energy from 0.5 s after the stop to the end
  bool finite = true;
};

constexpr double kRodSwingMass = 0.4;   // kg: 40 x 4 x 4 cm
constexpr double kRodSwingK = 300.0;    // N/m per finger

// The rod hangs from two fingers (k, 1 N s/m, `squeeze` deep, mu = 1) pinching it across y 3 cm
// below its top; the hand moves along x, A sin(w (t - 0.3)) for `cycles` cycles from 0.3 s, then
// holds still until 5 s. Energy: the rod's mechanical energy plus the finger springs' |f|^2 / (2k),
// less its value hanging at rest (the same scene with A = 0, at its end).
SwingOutcome rod_swing(int physics, double squeeze, double amplitude, double w, double cycles) {
  const double half_w = 0.02, L = 0.4, top = 0.65, grip = top - 0.03;
  Model m;
  m.rates.physics = physics;
  m.bodies.push_back(make_box("rod", kRodSwingMass, Vec3(half_w, half_w, L / 2.0), Vec3(0.0, 0.0, top - L / 2.0),
                              Material{1.0, kInfinity, kInfinity}));
  m.fingers.push_back(make_finger("thumb", kRodSwingK, 1.0));
  m.fingers.push_back(make_finger("index", kRodSwingK, 1.0));
  const double t0 = 0.3, t1 = t0 + cycles * 2.0 * M_PI / w;
  const auto energy_run = [&](double a, SwingOutcome* out) {
    Simulation sim(m);
    double spring = 0.0;
    double e = 0.0;
    run(sim, 3000 * 5,
        [&](std::size_t i, double t) {
          const double x = t < t0 ? 0.0 : a * std::sin(w * (std::min(t, t1) - t0));
          return Vec3(x, (i == 0 ? -1.0 : 1.0) * (half_w - squeeze), grip);
        },
        [&](const TickRecord& r) {
          spring = (r.servo[0].force.squaredNorm() + r.servo[1].force.squaredNorm()) / (2.0 * kRodSwingK);
          e = mechanical_energy(m, sim.state()) + spring;
          if (out == nullptr) return;
          const double t = sim.time();
          if (r.haptic_ran) {
            for (int f = 0; f < 2; ++f) {
              const HapticFingerRecord& h = r.haptic[f];
              out->held = out->held && h.body == 0;
              if (t <= 0.2 || h.depth <= 0.0) continue;
              out->slip += h.slip;
              const Vec3 n = (h.surface_point - r.servo[f].hip) / h.depth;
              const double fn = r.servo[f].force.dot(n);
              out->worst_ratio = std::max(out->worst_ratio, (r.servo[f].force - fn * n).norm() / fn);
            }
          }
          if (!r.physics_ran) return;
          const BodyState& b = sim.state().bodies[0];
          out->widest = std::max(out->widest, std::acos(std::min(1.0, b.rotation(2, 2))));
          out->finite = out->finite && finite(b);
          if (out->e_stop == 0.0 && t >= t1) out->e_stop = e;
          if (t > t1 + 0.5) out->e_after = std::max(out->e_after, e);
        });
    return e;
  };
  const double e_rest = energy_run(0.0, nullptr);
  SwingOutcome out;
  energy_run(amplitude, &out);
  out.e_stop -= e_rest;
  out.e_after -= e_rest;
  return out;
}

}  // namespace

// Section 6: a rod held at one end follows an arc while there is no slip at the grasp points. The
// hard variant of scenarios/rod_swing.lua: a 40 cm rod pinched 3 cm from its top (its pendulum
// about the grip: w0 = sqrt(m g r / J) = 6.3 rad/s, r = 17 cm, J = 0.017 kg m^2), swung by a hand
// that moves +-3 cm at up to 25 rad/s (four times w0; peak hand acceleration 19 m/s^2, 1.9 g) for
// three cycles. The grip: squeeze 1.5 cm, 4.5 N normal per finger, mu = 1.
//  - No NaN, and the fingers keep the rod at every haptic tick (no slip-out).
//  - The grip holds: each finger's force stays inside its friction cone, |f_t| <= mu f_n (the
//    engine clamps it there, so <= 1 + 1e-9), and the god-objects slip less than 0.5 mm in all
//    (measured 0 up to 15 rad/s; 0.46 mm at 25 rad/s at 50 Hz, 0 at 500 and 3000 Hz).
//  - Energy bounded once the hand holds still: nothing drives the rod, the finger dampers take
//    energy out, and the swing energy (rod and finger springs, above hanging at rest) 0.5 s after
//    the stop (the grip's own ringing, 69 rad/s at damping ratio 0.12, has decayed) never exceeds
//    its value at the stop by more than the scheme's own wobble: symplectic Euler's energy
//    oscillates by a fraction h w0 of a swing's energy (about h w0 / 2 either side of the conserved
//    modified energy), 13% at 50 Hz, 1.3% at 500 Hz. Checked against (1 + h w0) x E_stop plus
//    1 mJ for the springs' residual ringing (the swing energies at the stop are 10 to 69 mJ;
//    measured at most +3% after, at 50 Hz and 5 rad/s).
// The grip's mode (m_eff = 0.13 kg at the grip on 2k = 600 N/m) has h^2 2k / m_eff = 1.9 at 50 Hz:
// inside the stability bound 4 - 2 h C / m_eff = 3.4. A grip stiff enough to carry a heavier swing
// is not: k = 600 N/m per finger gives 3.8 > 3.4 at 50 Hz.
TEST_CASE("a long rod swung fast from one end keeps its grip and its energy", "[hard][grasp][law]") {
  const double w0 = std::sqrt(kRodSwingMass * kG * 0.17 / (kRodSwingMass * (0.16 + 0.0016) / 12.0 + kRodSwingMass * 0.17 * 0.17));
  for (int rate : {50, 500, 3000}) {
    for (double w : {5.0, 10.0, 15.0, 25.0}) {
      const SwingOutcome o = rod_swing(rate, 0.015, 0.03, w, 3.0);
      INFO("physics " << rate << " Hz, hand at " << w << " rad/s: swung to " << o.widest << " rad, slip " << o.slip
                      << " m, |f_t| / mu f_n up to " << o.worst_ratio << ", swing energy " << o.e_stop << " J at the stop, "
                      << o.e_after << " J at most after");
      CHECK(o.finite);
      CHECK(o.held);
      CHECK(o.worst_ratio <= 1.0 + 1e-9);
      CHECK(o.slip < 5e-4);
      CHECK(o.e_stop > 0.005);
      CHECK(o.e_after <= (1.0 + w0 / rate) * o.e_stop + 1e-3);
    }
  }
}

// The checks above can fail: the same swing with a grip too weak to carry the rod (squeeze 4 mm:
// 2 mu k d = 2.4 N < m g = 3.9 N) loses it: the rod slides down out of the fingers before the
// swing starts, and falls.
TEST_CASE("a rod gripped below m g / (2 mu k) slides out of the grip", "[hard][grasp][law]") {
  for (int rate : {50, 500}) {
    const SwingOutcome o = rod_swing(rate, 0.004, 0.03, 10.0, 3.0);
    CHECK_FALSE(o.held);
  }
}

