// The laws behind the benchmark's contact accuracy scenes (tools/bench/contact_accuracy.hpp):
// that each scene is built as it says (where the cube rests, which way the slope runs, how many
// physics steps the cost is divided by), checked where the answer is known exactly. The scenes'
// accuracy itself is measured by graspsim_bench, not asserted here. Engine only.
#include <catch2/catch.hpp>

#include <cmath>

#include "bench/contact_accuracy.hpp"
#include "graspsim/engine/simulation.hpp"

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

// The implicit step's slide down 30 degrees (mu 0.5) against Coulomb's a t^2 / 2, a = g (sin t -
// mu cos t) = 0.657 m/s^2, by order (engine/README.md, "Second order"). The sliding cube's velocity
// follows a t under either order (its equation is linear in t). Backward Euler moves it by h v1 a
// step, x_k = a h^2 k (k + 1) / 2 = a t^2 / 2 + a h t / 2: 2 % long after 1 s at 50 Hz. BDF2
// reproduces a t^2 / 2 exactly; it starts after kSettledSteps = 3 backward Euler steps (restarts)
// whose errors e_2 = a h^2, e_3 = 3 a h^2 / 2 it carries as e_{n+1} = (4 e_n - e_{n-1}) / 3 to
// the constant (3 e_3 - e_2) / 2 = 7/4 a h^2. The cube starts touching with no force: over the
// first step its normal force, and with it friction, builds up from zero, so it slides a little
// further (measured: 2.26 a h^2 in all, the same at every rate from 50 Hz to 3 kHz). Bounds:
// BDF2 within 3/4 a h^2 of 7/4 a h^2 (and within the 0.5 % at every rate), backward Euler
// within 3 a h^2 of its a h t / 2 law (measured 25.01 a h^2 at 50 Hz, 1500.01 at 3 kHz), so the
// test sees which scheme ran: at 50 Hz the two differ by 23 a h^2.
TEST_CASE("BDF2 slides Coulomb's distance where backward Euler runs h t / 2 ahead", "[bench][law]") {
  const double slope = 30.0 * kPi / 180.0, t = 1.0;
  const double a = 9.81 * (std::sin(slope) - 0.5 * std::cos(slope));   // m/s^2
  for (int rate : {50, 100, 250, 500, 1000, 3000}) {
    const double h = 1.0 / rate;
    for (int order : {1, 2}) {
      Model m = contact_model(rate, Integrator::kImplicit, slope);
      m.implicit_order = order;
      Simulation sim(m);
      Input in = make_input(m);
      TickRecord rec = make_tick_record(m);
      for (int n = 0; n < m.rates.servo; ++n) sim.step(in, rec);
      const double slide = sim.state().bodies[0].position.x() - m.bodies[0].position.x();
      const double error = slide - analytic_slide(slope, 0.5, t);
      INFO("order " << order << " at " << rate << " Hz: slide " << slide << " m, error " << error / (a * h * h)
                    << " a h^2 (" << 100.0 * error / analytic_slide(slope, 0.5, t) << " %)");
      if (order == 2) {
        CHECK(std::abs(error - 1.75 * a * h * h) <= 0.75 * a * h * h);
        CHECK(std::abs(error) <= 0.005 * analytic_slide(slope, 0.5, t));
      } else {
        CHECK(std::abs(error - 0.5 * a * h * t) <= 3.0 * a * h * h);
      }
    }
  }
}
