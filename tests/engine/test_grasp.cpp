// Two-finger grasps: the residual wrench of finger forces on a body (paper, section 3.1) and
// the pinch threshold that follows from the friction cone.
#include <catch2/catch.hpp>

#include <cmath>

#include "tests/engine/harness.hpp"

using namespace graspsim;
using graspsim::test::make_box;
using graspsim::test::make_finger;
using graspsim::test::run;

namespace {

struct PinchOutcome {
  double drop;         // m: how far the box fell in 1 s
  double slip;         // m: total god-object slip of both fingers
  double speed;        // m/s: box speed at the end
};

// Box of mass m and half size 4 cm, no floor, gripped from t = 0 by two fingers at +-x pressed
// in by depth d (their HIPs start inside the box, so the nearest faces, +-x, are taken; the
// faces a moving finger enters are tested in test_friction_cone.cpp). Fingers never move. A
// grip formed on a box already falling would let it slip while the depth, and with it the
// friction circle, builds up: physical, but not the static law tested here.
//
// Physics at 500 Hz: the law does not depend on the rate, but the explicit integration does.
// At the paper's 50 Hz the coupling must satisfy h^2 (2k/m) < 4 - 2 h C/m, which caps k/m so
// low that the grip depth d = m g / (2 mu k) exceeds the 4 cm half size for mu = 0.3; and
// without near-critical damping the box would overshoot to twice its sag and slip early. The
// two-finger lift scenario shows the grasp at the paper's rates end to end.
PinchOutcome pinch(double mass, double mu, double k, double d) {
  Model m;
  m.rates.physics = 500;
  const Vec3 h(0.04, 0.04, 0.04);
  m.bodies.push_back(make_box("box", mass, h, Vec3::Zero(), Material{mu, kInfinity, kInfinity}));
  // Critical damping of the vertical mode: stiffness 2k, so c_total = 2 sqrt(2k m), per finger
  // half that. Without damping the box would overshoot to twice its static sag and slip early.
  const double c = std::sqrt(2.0 * k * mass);
  m.fingers.push_back(make_finger("thumb", k, c));
  m.fingers.push_back(make_finger("index", k, c));
  Simulation sim(m);
  PinchOutcome out{0.0, 0.0, 0.0};
  run(sim, 3000, [&](std::size_t i, double) {
        return Vec3(i == 0 ? -(h.x() - d) : (h.x() - d), 0.0, 0.0);
      },
      [&](const TickRecord& r) {
        if (r.haptic_ran) out.slip += r.haptic[0].slip + r.haptic[1].slip;
      });
  out.drop = -sim.state().bodies[0].position.z();
  out.speed = sim.state().bodies[0].velocity.norm();
  return out;
}

}  // namespace

// Pinch threshold. Two opposed fingers with grip N = k d each can carry a tangential force
// of mu N each, so a box of weight m g hangs without slip when 2 mu N > m g and slides when
// 2 mu N < m g. With 10% margin either side: held, the box sags only by the spring stretch
// m g / (2 k) (checked with 5% allowance for the discrete filter's overshoot) and no
// god-object moves; too weak, it falls by far more than that (over 1 cm in 1 s).
TEST_CASE("a pinched box lifts without slip above the friction threshold and slides below it",
          "[grasp][law]") {
  const double g = 9.81, k = 2000.0;   // stiff enough that d stays well inside the 4 cm half size
  for (double mass : {0.2, 1.0}) {
    for (double mu : {0.3, 0.8}) {
      INFO("mass " << mass << " kg, mu " << mu);
      const double d_threshold = mass * g / (2.0 * mu * k);   // 2 mu k d = m g
      const PinchOutcome held = pinch(mass, mu, k, 1.1 * d_threshold);
      const double sag = mass * g / (2.0 * k);
      CHECK(held.slip == 0.0);
      CHECK(held.drop == Approx(sag).epsilon(0.05));
      CHECK(held.speed < 1e-3);
      const PinchOutcome dropped = pinch(mass, mu, k, 0.9 * d_threshold);
      CHECK(dropped.slip > 0.01);
      CHECK(dropped.drop > 0.01);
    }
  }
}

// Residual torque T = sum r_i x f_i (paper, section 3.1). A finger pushing the +x face of a
// free box in -x at y = +2 cm applies f = (-F, 0, 0) at r = (h, 0.02, 0), so T = r x f =
// (0, 0, 0.02 F): about +z, and the box starts to spin positively about z. With one servo
// tick in the first window the recorded torque is that exactly (to rounding, 1e-12 relative).
TEST_CASE("an off-centre push turns the body about the right axis with the right sign",
          "[residual][law]") {
  Model m;
  m.gravity = Vec3::Zero();
  m.rates = Rates{3000, 3000, 3000};
  const Vec3 h(0.05, 0.05, 0.05);
  m.bodies.push_back(make_box("box", 0.5, h, Vec3::Zero()));
  m.fingers.push_back(make_finger("finger", 300.0));
  Simulation sim(m);
  // The HIP starts outside at x = 0.06 and moves in: it enters at t > 0.
  bool checked = false;
  run(sim, 300, [](std::size_t, double t) { return Vec3(0.06 - 0.2 * t, 0.02, 0.0); },
      [&](const TickRecord& r) {
        if (checked || r.servo[0].force.isZero()) return;
        // First tick with a force: the body has not moved yet, and the window is this tick.
        const Vec3 f_body = -r.servo[0].force;
        const BodyRecord& b = r.physics[0];
        REQUIRE(f_body.x() < 0.0);
        REQUIRE(b.force.isApprox(f_body, 1e-12));
        const Vec3 expected_torque = Vec3(h.x(), 0.02, 0.0).cross(f_body);
        REQUIRE(expected_torque.z() > 0.0);
        REQUIRE(b.torque.isApprox(expected_torque, 1e-12));
        checked = true;
      });
  REQUIRE(checked);
  const Vec3 w = sim.state().bodies[0].angular_velocity;
  CHECK(w.z() > 0.0);
  CHECK(std::abs(w.x()) < 1e-12 * w.z());
  CHECK(std::abs(w.y()) < 1e-12 * w.z());
}
