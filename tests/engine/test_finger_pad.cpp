// Finger pads of finite radius (engine/README.md, "Finger pads"): a sphere of radius r touching a
// face is its centre (the HIP) touching the face moved out by r; the force acts on the surface.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "tests/engine/harness.hpp"

using namespace graspsim;

// A pad of radius r = 1 cm over a rigid floor (z = 0): free while its centre is above z = r;
// below, pressed d = r - z deep, f_n = k d, and the friction circle holds as for a point:
// dragged sideways, f_t <= mu f_n, with equality while sliding. Forces to 1e-12 relative.
TEST_CASE("a spherical pad touches at one radius and obeys the friction cone", "[finger_contact][pad][law]") {
  const double r = 0.01, k = 800.0, mu = 0.5;
  Model m;
  m.floor.enabled = true;
  m.floor.material = Material{mu, kInfinity, kInfinity};
  FingerParams f = graspsim::test::make_finger("pad", k);
  f.radius = r;
  m.fingers.push_back(f);
  Simulation sim(m);
  // Down from z = 2 cm to z = 0.6 cm (4 mm deep) in 0.2 s, then 2 cm sideways in 0.5 s.
  const auto hip = [](std::size_t, double t) {
    return Vec3(0.02 * std::clamp((t - 0.3) / 0.5, 0.0, 1.0), 0.0, 0.02 - 0.014 * std::min(t / 0.2, 1.0));
  };
  int free_above = 0, pressed = 0, sliding = 0;
  graspsim::test::run(sim, 3000, hip, [&](const TickRecord& rec) {
    if (!rec.haptic_ran) return;
    const double z = rec.servo[0].hip.z();
    const HapticFingerRecord& h = rec.haptic[0];
    if (z > r) {
      REQUIRE(h.phase == ContactPhase::kFree);
      ++free_above;
      return;
    }
    REQUIRE(h.phase != ContactPhase::kFree);
    REQUIRE(h.depth == Approx(r - z).epsilon(1e-12));
    REQUIRE(h.force.z() == Approx(k * (r - z)).epsilon(1e-12));
    const double f_t = std::hypot(h.force.x(), h.force.y());
    REQUIRE(f_t <= mu * h.force.z() * (1.0 + 1e-12));
    if (h.phase == ContactPhase::kSlip) {
      REQUIRE(f_t == Approx(mu * h.force.z()).epsilon(1e-9));
      ++sliding;
    }
    ++pressed;
  });
  CHECK(free_above > 10);
  CHECK(pressed > 100);
  CHECK(sliding > 50);
}

// The reaction acts where the pad touches the surface, r below its centre. A pad pressing the
// top face of a free box (no gravity, every loop at 3000 Hz so each physics window is one tick)
// and dragging along x pushes the box with f = -f_finger at the contact point c_p = GO - r n:
// the recorded torque is (c_p - c) x f to 1e-12, and differs from the torque about the pad's
// centre by |r n x f| (> 1e-5 N m here), so the test tells the two apart.
TEST_CASE("a pad's force acts on the surface, one radius below its centre", "[finger_contact][pad][law]") {
  const double r = 0.01;
  Model m;
  m.gravity = Vec3::Zero();
  m.rates = Rates{3000, 3000, 3000};
  m.bodies.push_back(graspsim::test::make_box("box", 1.0, Vec3(0.05, 0.05, 0.05), Vec3::Zero(),
                                              Material{0.8, kInfinity, kInfinity}));
  FingerParams f = graspsim::test::make_finger("pad", 500.0);
  f.radius = r;
  m.fingers.push_back(f);
  Simulation sim(m);
  const auto hip = [](std::size_t, double t) {
    return Vec3(0.01 * std::max(0.0, t - 0.05) / 0.05, 0.0, 0.065 - 0.01 * std::min(t / 0.05, 1.0));
  };
  int checked = 0;
  graspsim::test::run(sim, 300, hip, [&](const TickRecord& rec) {
    const Vec3& force = rec.servo[0].force;
    if (rec.haptic[0].phase == ContactPhase::kFree || std::abs(force.x()) < 1e-3) return;
    const BodyRecord& b = rec.physics[0];
    const Vec3 normal = b.orientation * Vec3::UnitZ();   // the top face's normal: the box turns
    const Vec3 contact = rec.haptic[0].god_object - r * normal;
    const Vec3 expected = (contact - b.position).cross(-force);
    REQUIRE((b.torque - expected).norm() <= 1e-12 * expected.norm());
    const Vec3 about_centre = (rec.haptic[0].god_object - b.position).cross(-force);
    const double lever = r * normal.cross(force).norm();   // |r n x f|, about r |f_x| here
    REQUIRE((about_centre - expected).norm() == Approx(lever).epsilon(1e-9));
    REQUIRE(lever > 1e-5);
    ++checked;
  });
  CHECK(checked > 50);
}
