// Torsion about a two-finger grasp axis (paper, section 3.2) and the torque dead band (5).
#include <catch2/catch.hpp>

#include <cmath>

#include "graspsim/engine/grasp_rules.hpp"
#include "tests/engine/harness.hpp"

using namespace graspsim;

namespace {

// A rod 20 x 4 x 4 cm, 0.2 kg, with its centre at (0, 0, 0.3), pinched across y by two fingers
// 8 cm from its centre (x = -0.08), each pressed `squeeze` deep: the grasp axis is y, through
// the god-objects at (-0.08, -+0.02, 0), and the centre hangs 8 cm out along x.
constexpr double kMass = 0.2;
const Vec3 kHalf(0.1, 0.02, 0.02);

Model rod_scene(Torsion torsion, double critical_area, int physics) {
  Model m;
  m.rates.physics = physics;
  m.grasp.torsion = torsion;
  m.grasp.critical_area = critical_area;
  m.bodies.push_back(graspsim::test::make_box("rod", kMass, kHalf, Vec3(0.0, 0.0, 0.3),
                                              Material{1.0, kInfinity, kInfinity}));
  m.fingers.push_back(graspsim::test::make_finger("thumb", 400.0, 2.0));
  m.fingers.push_back(graspsim::test::make_finger("index", 400.0, 2.0));
  return m;
}

Vec3 pinch(std::size_t finger, double squeeze) {
  const double y = kHalf.y() - squeeze;
  return Vec3(-0.08, finger == 0 ? -y : y, 0.3);
}

double angle_about_y(const Quat& q) {
  const Eigen::AngleAxisd aa(q);
  return aa.angle() * aa.axis().y();
}

}  // namespace

// The gravity-drop law, one step by hand. At rest, the first physics step (tick 0) sees both
// fingers 8 mm deep with mu = 1: friction radius r = 8 mm, A = pi r^2 = 2.01e-4 m^2. With
// A_crit = 1e-3 m^2, p = c - GO_thumb = (0.08, 0.02, 0) and m g = (0, 0, -1.962 N):
//   T_drop = [p x m g (1 - A/A_crit)] . u,  u = +y,  (p x m g) . y = p_z m g_x - p_x m g_z
//          = 0.08 x 1.962 = 0.15696 N m, times (1 - 0.201) = 0.12541 N m,
// and the hinge about the axis gives w_y = dt T_drop / J_axis after the step, with
// J_axis = J_yy + m |p_perp|^2 = m (0.2^2 + 0.04^2) / 12 + m 0.08^2. Computed here from those
// formulas, not from the engine's values; tolerance 1e-12 relative (rounding only).
TEST_CASE("gravity-induced drop applies [p x m g (1 - A/A_crit) . u] about the grasp axis",
          "[torsion][law]") {
  Simulation sim(rod_scene(Torsion::kGravityDrop, 1e-3, 50));
  TickRecord first;
  graspsim::test::run(sim, 1, [](std::size_t f, double) { return pinch(f, 0.008); },
                      [&](const TickRecord& r) { first = r; });
  const double area = M_PI * 0.008 * 0.008;
  const double t_drop = 0.08 * kMass * 9.81 * (1.0 - area / 1e-3);
  const double j_axis = kMass * (0.2 * 0.2 + 0.04 * 0.04) / 12.0 + kMass * 0.08 * 0.08;
  REQUIRE(first.physics_ran);
  CHECK(first.physics[0].grasp_area == Approx(area).epsilon(1e-12));
  CHECK(first.physics[0].torsion == Approx(t_drop).epsilon(1e-12));
  CHECK(sim.state().bodies[0].angular_velocity.y() == Approx(t_drop / j_axis / 50.0).epsilon(1e-12));
  // The hinge turns the centre about the axis, not the axis about the centre: the rotation adds
  // no velocity to the axis point, which only gets the step's translational impulse F dt / m.
  const BodyState& b = sim.state().bodies[0];
  const Vec3 axis_point(-0.08, -0.02, 0.3);
  const Vec3 v_axis = b.velocity + b.angular_velocity.cross(axis_point - Vec3(0.0, 0.0, 0.3));
  CHECK((v_axis - first.physics[0].force / kMass / 50.0).norm() < 1e-12);
}

// Above A_crit the finger pads' torsional friction holds: no rotation about the grasp axis. The
// rod, whose centre hangs 8 cm out, stays level for 3 s (angle about y below 1e-12 rad: the rule
// zeroes w_y at every step, so only rounding remains) at the paper's 50 Hz and at 500 Hz; with
// A_crit twice as large (A below it) the same grasp lets it drop by more than 1 rad.
TEST_CASE("no rotation about the grasp axis while the friction circles exceed A_crit",
          "[torsion][law]") {
  for (int physics : {50, 500}) {
    const double area = M_PI * 0.008 * 0.008;   // 2.01e-4 m^2
    Simulation held(rod_scene(Torsion::kGravityDrop, 0.9 * area, physics));
    double worst = 0.0;
    graspsim::test::run(held, 3000 * 3, [](std::size_t f, double) { return pinch(f, 0.008); },
                        [&](const TickRecord& r) {
                          if (r.physics_ran) worst = std::max(worst, std::abs(angle_about_y(r.physics[0].orientation)));
                        });
    INFO("physics " << physics << " Hz");
    CHECK(worst < 1e-12);
    Simulation dropped(rod_scene(Torsion::kGravityDrop, 2.0 * area, physics));
    double deepest = 0.0;
    graspsim::test::run(dropped, 3000 * 1, [](std::size_t f, double) { return pinch(f, 0.008); },
                        [&](const TickRecord& r) {
                          if (r.physics_ran) deepest = std::max(deepest, angle_about_y(r.physics[0].orientation));
                        });
    CHECK(deepest > 1.0);
  }
}

// Below A_crit the body swings about the grasp axis as a pendulum with the paper's reduced
// gravity: small swings have period T = 2 pi sqrt(J_axis / (m g d (1 - A/A_crit))), d = 8 cm
// the centre's distance from the axis. Released 0.1 rad from hanging straight down, at 500 Hz,
// the measured period (mean of 3 periods between upward zero crossings of w_y) is within 0.5%:
// the swing's amplitude lengthens it by 0.06%, the first-order integration and the 2 ms
// sampling of the crossings by less than 0.3% (measured error 0.05-0.08%); the rod stays held.
TEST_CASE("below A_crit the grasped body swings about the grasp axis with the reduced gravity",
          "[torsion][law]") {
  const double area = M_PI * 0.008 * 0.008;
  Model m = rod_scene(Torsion::kGravityDrop, 2.0 * area, 500);
  // Hanging 0.1 rad short of straight down: turned about the grasp axis (y) through the GOs.
  const double start = M_PI / 2.0 - 0.1;
  const Vec3 pivot(-0.08, 0.0, 0.3);
  const Mat3 turn = Eigen::AngleAxisd(start, Vec3::UnitY()).toRotationMatrix();
  m.bodies[0].orientation = Quat(turn);
  m.bodies[0].position = pivot + turn * (Vec3(0.0, 0.0, 0.3) - pivot);
  Simulation sim(m);
  std::vector<double> crossings;
  double last_w = 0.0;
  graspsim::test::run(sim, 3000 * 4, [&](std::size_t f, double) { return pinch(f, 0.008); },
                      [&](const TickRecord& r) {
                        if (!r.physics_ran) return;
                        const double w = r.physics[0].angular_velocity.y();
                        if (r.tick > 0 && last_w < 0.0 && w >= 0.0) crossings.push_back(r.tick / 3000.0);
                        last_w = w;
                        REQUIRE(r.physics[0].grasp_area > 0.0);   // still held
                      });
  REQUIRE(crossings.size() >= 4);
  const double period = (crossings[3] - crossings[0]) / 3.0;
  const double j_axis = kMass * (0.2 * 0.2 + 0.04 * 0.04) / 12.0 + kMass * 0.08 * 0.08;
  const double expected = 2.0 * M_PI * std::sqrt(j_axis / (kMass * 9.81 * 0.08 * 0.5));
  CHECK(period == Approx(expected).epsilon(0.005));
}

// Instrumented gimbal (section 3.2, solution 1): above A_crit a pitch change of the gimbal
// finger turns the body about the axis through the god-objects by exactly that angle: the
// orientation by R(u, d) and the centre on a circle about the axis, the axis points fixed.
TEST_CASE("a gimbal pitch change turns the grasped body about the grasp axis", "[torsion][law]") {
  Model m = rod_scene(Torsion::kGimbal, 1e-4, 50);
  m.grasp.gimbal_finger = 1;
  m.gravity = Vec3::Zero();
  BodyState bs;
  bs.position = Vec3(0.0, 0.0, 0.3);
  TwoPointGrasp g;
  g.held = true;
  g.go_first = Vec3(-0.08, -0.02, 0.3);
  g.axis = Vec3::UnitY();
  g.area = 2e-4;   // above A_crit
  Vec3 torque(0.1, 0.2, 0.3);
  const double turned = gimbal_twist(m, 0, g, 0.25, bs, torque);
  CHECK(turned == 0.25);
  const Mat3 expected = Eigen::AngleAxisd(0.25, Vec3::UnitY()).toRotationMatrix();
  CHECK((bs.rotation - expected).norm() < 1e-15);
  const Vec3 centre = g.go_first + expected * (Vec3(0.0, 0.0, 0.3) - g.go_first);
  CHECK((bs.position - centre).norm() < 1e-15);
  CHECK(torque.y() == 0.0);   // the residual about the axis is replaced by the gimbal
  CHECK(torque.x() == 0.1);
  // Below A_crit the gimbal does nothing.
  BodyState free;
  g.area = 0.5e-4;
  Vec3 t2(0.1, 0.2, 0.3);
  CHECK(gimbal_twist(m, 0, g, 0.25, free, t2) == 0.0);
  CHECK(free.rotation == Mat3::Identity());
  CHECK(t2 == Vec3(0.1, 0.2, 0.3));
}

// The dead band (section 5): a residual torque of magnitude at most T_crit is set to zero, a
// larger one is left exactly as it is.
TEST_CASE("the dead band zeroes torques up to T_crit and leaves larger ones", "[torsion][law]") {
  for (double t_crit : {1e-4, 0.01, 1.0}) {
    Vec3 inside = Vec3(0.6, 0.0, 0.8) * t_crit;   // |T| = T_crit exactly
    dead_band(t_crit, inside);
    CHECK(inside == Vec3::Zero());
    const Vec3 original = Vec3(0.6, 0.0, 0.8) * (t_crit * 1.001);
    Vec3 outside = original;
    dead_band(t_crit, outside);
    CHECK(outside == original);
  }
  Vec3 any(1e-9, 0.0, 0.0);
  dead_band(0.0, any);   // T_crit = 0: no band
  CHECK(any.x() == 1e-9);
}

// The hinge is about the grasp axis only: the floor still pushes. A 12 x 4 x 4 cm box resting on
// the floor, pinched lightly across y 4 cm off its centre with A < A_crit, is held up at its far
// end by the floor: the scaled gravity torque about the axis (m g d / 2 = 0.078 N m) is balanced
// by the floor's, which needs its far springs (2 x 100 N/m, 0.1 m from the axis) compressed by
// ~4 mm: a tilt of ~0.04 rad, 0.06 with the first overshoot. So the tilt stays below 0.1 rad
// (it is 0.46 rad, and the box tears out of the grasp, if the floor's torque about the axis is
// dropped), the box comes to rest, and the fingers keep it.
TEST_CASE("a pinched box resting on the floor is not turned through it by the gravity drop",
          "[torsion][law]") {
  Model m;
  m.grasp.torsion = Torsion::kGravityDrop;
  m.floor.enabled = true;
  m.floor.material = Material{0.6, 100.0, 1.0};
  const Vec3 h(0.06, 0.02, 0.02);
  const double rest = h.z() - 0.4 * 9.81 / 400.0;
  m.bodies.push_back(graspsim::test::make_box("box", 0.4, h, Vec3(0.0, 0.0, rest), Material{0.8, kInfinity, kInfinity}));
  m.fingers.push_back(graspsim::test::make_finger("thumb", 300.0, 2.0));
  m.fingers.push_back(graspsim::test::make_finger("index", 300.0, 2.0));
  const double squeeze = 0.003;
  m.grasp.critical_area = 2.0 * M_PI * std::pow(0.8 * squeeze, 2);
  Simulation sim(m);
  double worst = 0.0;
  bool held = true;
  graspsim::test::run(sim, 3000 * 2,
                      [&](std::size_t f, double) { return Vec3(-0.04, f == 0 ? -(h.y() - squeeze) : h.y() - squeeze, rest); },
                      [&](const TickRecord& r) {
                        if (!r.physics_ran) return;
                        worst = std::max(worst, std::abs(angle_about_y(r.physics[0].orientation)));
                        if (r.tick > 300) held = held && r.physics[0].grasp_area > 0.0;
                      });
  CHECK(worst < 0.1);
  CHECK(held);
  CHECK(sim.state().bodies[0].angular_velocity.norm() < 1e-3);
}

// Above A_crit the lock holds about any axis, not only a principal one. Fingers pinching the rod
// at different heights (z = -+1 cm) make the axis skewed in the y-z plane; the rod, without
// gravity, is set spinning about a general direction, so the finger springs' torques have
// components that would turn it about u through the off-diagonal inertia (0.26 rad/s leaks
// when the rate is not protected). The rate about u must stay zero: below 1e-6 rad/s, since the
// check takes u after the step and the rule before it (measured 1.5e-9). At 500 Hz: at 50 Hz this
// spinning rod's rotation against the finger springs 8 cm away (K/I ~ 7400 s^-2, (w h)^2 ~ 3)
// is at the explicit stability bound and tears out of the grasp.
TEST_CASE("the lock above A_crit holds about an axis that is not principal", "[torsion][law]") {
  const double area = M_PI * 0.008 * 0.008;
  Model m = rod_scene(Torsion::kGravityDrop, 0.5 * area, 500);
  m.gravity = Vec3::Zero();
  m.bodies[0].angular_velocity = Vec3(0.5, 0.3, 0.2);
  Simulation sim(m);
  double worst = 0.0;
  graspsim::test::run(sim, 3000 * 2,
                      [](std::size_t f, double) { return Vec3(-0.08, f == 0 ? -0.012 : 0.012, f == 0 ? 0.29 : 0.31); },
                      [&](const TickRecord& r) {
                        if (!r.physics_ran || r.tick == 0) return;
                        const State& s = sim.state();
                        const BodyState& b = s.bodies[0];
                        const Vec3 g1 = b.rotation * s.fingers[0].god_object + b.position;
                        const Vec3 g2 = b.rotation * s.fingers[1].god_object + b.position;
                        const Vec3 u = (g2 - g1).normalized();
                        // Skewed indeed at the first step (body-frame u near (0, 0.89, 0.45)); the
                        // god-objects then slide as the rod turns and the axis drifts.
                        if (r.tick == 6) REQUIRE((b.rotation.transpose() * u).cwiseAbs().maxCoeff() < 0.95);
                        REQUIRE(r.physics[0].grasp_area > 0.0);   // still held
                        worst = std::max(worst, std::abs(b.angular_velocity.dot(u)));
                      });
  CHECK(worst < 1e-6);
}

// The gimbal's sense does not depend on the order in which the fingers are listed: the same
// pitch ramp of the same physical finger turns the body the same way (to rounding, 1e-12).
TEST_CASE("the gimbal turns the body the same way whatever the finger order", "[torsion][law]") {
  Mat3 final_rotation[2];
  for (int order = 0; order < 2; ++order) {
    Model m = rod_scene(Torsion::kGimbal, 1e-5, 50);
    m.gravity = Vec3::Zero();
    if (order == 1) std::swap(m.fingers[0], m.fingers[1]);
    const int gimbal = order == 0 ? 0 : 1;   // the finger called "thumb", at -y
    m.grasp.gimbal_finger = gimbal;
    Simulation sim(m);
    Input input = make_input(m);
    TickRecord record = make_tick_record(m);
    for (int n = 0; n < 3000; ++n) {
      const double t = sim.time();
      for (int f = 0; f < 2; ++f) {
        const bool thumb = m.fingers[f].name == "thumb";
        input.fingers[f].hip = pinch(thumb ? 0 : 1, 0.008);
        input.fingers[f].gimbal = Vec3(0.0, thumb ? 0.5 * t : 0.0, 0.0);   // pitch ramp, rad
      }
      sim.step(input, record);
    }
    final_rotation[order] = sim.state().bodies[0].rotation;
  }
  CHECK(Eigen::AngleAxisd(final_rotation[0]).angle() > 0.3);   // it did turn
  CHECK((final_rotation[0] - final_rotation[1]).norm() < 1e-12);
}
