// The laws behind the benchmark's contact accuracy scenes (tools/bench/contact_accuracy.hpp):
// that each scene is built as it says (where the cube rests, which way the slope runs, how many
// physics steps the cost is divided by), checked where the answer is known exactly. The scenes'
// accuracy itself is measured by graspsim_bench, not asserted here. Engine only.
#include <catch2/catch.hpp>

#include <cmath>

#include "bench/contact_accuracy.hpp"

using namespace graspsim;
using namespace graspsim::bench;

namespace {
constexpr double kPi = 3.14159265358979323846;
}

// Coulomb sliding from rest on an incline: a = g (sin t - mu cos t) while tan t > mu, else the
// block sticks (Goldstein 1.4). 30 degrees, mu 0.5: a = 9.81 (0.5 - 0.5 x 0.8660254) =
// 0.6571...; in 1 s x = a / 2 = 0.328573 m (hand computed to 6 digits, so 1e-5 relative). At
// tan t = mu exactly and below it is 0; the 24 degree slope (tan = 0.445) sticks.
TEST_CASE("the analytic slide is Coulomb's from rest, and zero where friction holds", "[bench][law]") {
  CHECK(analytic_slide(30.0 * kPi / 180.0, 0.5, 1.0) == Approx(0.328573).epsilon(1e-5));
  for (double t : {0.5, 1.0, 2.0})   // x grows as t^2
    CHECK(analytic_slide(30.0 * kPi / 180.0, 0.5, t) == Approx(0.328573 * t * t).epsilon(1e-5));
  CHECK(analytic_slide(24.0 * kPi / 180.0, 0.5, 1.0) == 0.0);
  CHECK(analytic_slide(std::atan(0.5), 0.5, 1.0) == 0.0);
  CHECK(analytic_slide(std::atan(0.5) + 0.01, 0.5, 1.0) > 0.0);
}

// Static equilibrium on four corner springs in parallel (Hooke): the soft floor's k per corner
// carries m g / 4, so the resting cube's centre is d = m g / (4 k) below its contact height;
// 1 kg on 250 N/m: 9.81 mm. The scene places the cube touching at t = 0 and lets it drop onto the
// springs; its vertical mode (4 k over m, damping 4 c) decays as exp(-2 c t / m) = exp(-5 t):
// after 5 s the residue is 9.8 mm x e^-25 ~ 1e-13 m, far below the 1e-9 relative tolerance
// (round-off of the equilibrium, which the symplectic step keeps exactly as its fixed point).
// A mirror-symmetric cube on four equal corners feels no torque: its tilt is round-off, < 1e-12 rad.
// Swept over the physics rate: the equilibrium does not depend on it.
TEST_CASE("a cube placed touching the paper's soft floor rests m g / (4 k) deep, level", "[bench][law]") {
  ContactSetup setup;
  setup.duration = 5.0;
  const double depth = setup.mass * 9.81 / (4.0 * setup.soft_stiffness * setup.mass);
  for (int rate : {50, 500, 3000}) {
    const RestResult r = run_rest(rate, Integrator::kPaper, setup);
    INFO(rate << " Hz: rests " << r.height_error << " m deep, tilt " << r.tilt << " rad");
    REQUIRE_FALSE(r.diverged);
    CHECK(r.height_error == Approx(depth).epsilon(1e-9));
    CHECK(r.tilt < 1e-12);
    CHECK(r.speed < 1e-9);
  }
}

// Which way the slope runs, and that gravity's tilt alone drives the slide: with mu = 0 no
// tangential force acts (the friction limit mu f_n is 0) and no torque either, so along the
// floor the cube follows the paper's step exactly, v_n = n h a, x_n = h^2 a n (n + 1) / 2 with
// a = g sin t down +x, whatever the normal spring does: after 1 s (n = rate) x = a (1 + h) / 2.
// Tolerance 1e-12 relative: round-off of summing n steps. Swept over rates and two slopes.
TEST_CASE("on a frictionless slope the cube slides down +x as the paper's step of g sin t", "[bench][law]") {
  ContactSetup setup;
  setup.mu = 0.0;
  for (double deg : {24.0, 30.0})
    for (int rate : {50, 500, 3000}) {
      const double slope = deg * kPi / 180.0, h = 1.0 / rate;
      const double expected = 0.5 * 9.81 * std::sin(slope) * (1.0 + h);
      const SlopeResult r = run_slope(rate, Integrator::kPaper, slope, setup);
      INFO(deg << " deg at " << rate << " Hz: slid " << r.slide << " m, sideways " << r.sideways << " m");
      REQUIRE_FALSE(r.diverged);
      CHECK(r.slide == Approx(expected).epsilon(1e-12));
      CHECK(r.sideways == 0.0);
    }
}

// The settling cost is divided by the physics steps run: 2 s at each rate is 2 x rate steps,
// with the idle servo and haptic loops or without (every loop at the physics rate).
TEST_CASE("the settling scene runs 2 s of physics steps at every rate", "[bench]") {
  for (bool alone : {false, true})
    for (int rate : {50, 500, 3000}) {
      ContactSetup setup;
      setup.loops_at_physics_rate = alone;
      const SettleResult r = run_settle(rate, Integrator::kPaper, setup);
      INFO(rate << " Hz, loops at the physics rate " << alone);
      REQUIRE_FALSE(r.diverged);
      CHECK(r.steps == 2 * rate);
    }
}

// The implicit scheme's default contact (engine/README.md, "Default contact"): k = m (4 pi f)^2
// per point, so the cube on its four bottom corners rests where 4 k d = m g, d = g / (4 (4 pi
// f)^2): 6.2 um at 50 Hz, falling as 1 / f^2. The default damping is critical and backward
// Euler damps more, so after 1 s the bounce is gone to round-off; the equilibrium is the step's
// fixed point, held to 1e-9 relative (round-off of the solve). Level to round-off (< 1e-12 rad)
// by symmetry, as on the soft floor.
TEST_CASE("under the implicit scheme a cube placed touching rests g / (4 (4 pi f)^2) deep, level",
          "[bench][law]") {
  for (int rate : {50, 500, 3000}) {
    const double w = 4.0 * kPi * rate;
    const RestResult r = run_rest(rate, Integrator::kImplicit);
    INFO(rate << " Hz: rests " << r.height_error << " m deep, tilt " << r.tilt << " rad");
    REQUIRE_FALSE(r.diverged);
    // 1e-9 relative, or 1e-15 m: at 3 kHz the depth (1.7 nm) is read off a centre height of
    // 0.05 m, whose ulp is 7e-18 m, so the relative bound alone would ask for less than an ulp.
    CHECK(r.height_error == Approx(9.81 / (4.0 * w * w)).epsilon(1e-9).margin(1e-15));
    CHECK(r.tilt < 1e-12);
  }
}

// Passivity (the implicit scheme's promise, engine/README.md, "Integrators"): springs, dampers
// and Coulomb friction only store or take energy, and the cube starts at rest with no spring
// stretched, so its kinetic and gravitational energy never rises above the start (E in
// contact_accuracy.hpp). Every scene, every rate: at rest, sticking on 24 degrees, sliding on 30,
// and dropped corner first. Tolerance 1e-12 J: E's terms are about 1 J, so round-off is ~1e-16 J
// a step (2e-16 J measured at rest), and a passive step only lowers E from there.
TEST_CASE("under the implicit scheme the cube's energy never rises above its start", "[bench][law]") {
  for (int rate : {50, 500, 3000}) {
    INFO(rate << " Hz");
    CHECK(run_rest(rate, Integrator::kImplicit).energy_gain <= 1e-12);
    CHECK(run_slope(rate, Integrator::kImplicit, 24.0 * kPi / 180.0).energy_gain <= 1e-12);
    CHECK(run_slope(rate, Integrator::kImplicit, 30.0 * kPi / 180.0).energy_gain <= 1e-12);
    CHECK(run_settle(rate, Integrator::kImplicit).energy_gain <= 1e-12);
  }
}
