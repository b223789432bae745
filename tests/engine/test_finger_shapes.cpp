// Finger contact on every shape kind in a Simulation: the force law on an analytic sphere, the
// friction cone over a traversed edge, and a two-finger grasp and lift of a sphere.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "graspsim/engine/grasp_rules.hpp"
#include "tests/engine/harness.hpp"
#include "tests/engine/shapes.hpp"

using namespace graspsim;
using graspsim::test::make_finger;


// Analytic sphere of R = 4 cm, frictionless, finger k = 800 N/m with a pad of r = 0 or 5 mm:
// f = k (R + r - |p - c|) (p - c)/|p - c| whenever |p - c| < R + r, else 0, at every tick
// (1e-9 relative: the body moves by < 1e-11 m and the checks use its recorded pose). The HIP
// spirals in from outside to 6 mm deep while turning round the sphere.
TEST_CASE("an analytic sphere pushes back radially with k (R + r - |p - c|)", "[finger_contact][sphere][law]") {
  const double R = 0.04, k = 800.0;
  for (double r : {0.0, 0.005}) {
    Model m;
    m.gravity = Vec3::Zero();
    m.rates = Rates{1000, 1000, 1000};
    m.bodies.push_back(graspsim::test::fixed_body("ball", sphere_shape(R), Material{0.0, kInfinity, kInfinity}));
    FingerParams f = make_finger("finger", k);
    f.radius = r;
    m.fingers.push_back(f);
    Simulation sim(m);
    const auto hip = [&](std::size_t, double t) {
      const double rho = R + r + 0.01 - 0.016 * std::min(t / 0.5, 1.0);
      const double a = 2.0 * t, b = 0.7 * t;
      return Vec3(rho * std::cos(a) * std::cos(b), rho * std::sin(a) * std::cos(b), rho * std::sin(b));
    };
    int pressed = 0, free = 0;
    graspsim::test::run(sim, 1000, hip, [&](const TickRecord& rec) {
      const Vec3 p = rec.servo[0].hip - rec.physics[0].position;
      const double depth = R + r - p.norm();
      if (depth <= 0.0) {
        REQUIRE(rec.servo[0].force.norm() == 0.0);
        ++free;
        return;
      }
      const Vec3 expected = k * depth * p.normalized();
      REQUIRE((rec.servo[0].force - expected).norm() <= 1e-9 * expected.norm());
      ++pressed;
    });
    CHECK(pressed > 600);
    CHECK(free > 100);
  }
}

// Friction over a traversal, on the convex ridge of a roof (normals turning by theta, tan(theta)
// = 4/3): a finger sticks near the ridge, 2 mm deep, and its HIP moves on level over the ridge.
// At the tick its SP switches to the right face, SP jumps by depth_L sin(theta) while the new
// depth is depth_L cos(theta): the chord from a GO at the ridge to SP is tan(theta) times the
// depth. Law (the paper's friction circle, measured along the chord GO-SP): the finger sticks,
// its GO exactly unchanged, at every tick where |GO - SP| <= mu depth, and slips at the first
// tick where it is not; with mu = 2 > tan(theta) it sticks with SP on the right face; with
// mu = 0.8 it breaks away at the switch. After slipping the GO is back on the surface (1e-12 m)
// within the friction circle; the force stays in the cone about the stored normal at every
// servo tick (1e-12).
TEST_CASE("a sticking finger does not slip over an edge while the chord is within mu depth", "[finger_contact][traversal][friction][law]") {
  const double w = 0.04, h = 0.02, k = 1000.0, d = 0.002;
  const ConvexPolyhedron roof = graspsim::test::wedge(w, h, 0.03);
  const Vec3 nL = Vec3(-h, 0.0, w).normalized(), nR = Vec3(h, 0.0, w).normalized();
  for (double mu : {2.0, 0.8}) {
    Model m;
    m.gravity = Vec3::Zero();
    m.rates = Rates{1000, 1000, 1000};
    m.bodies.push_back(graspsim::test::fixed_body("roof", graspsim::test::convex_shape(roof), Material{mu, kInfinity, kInfinity}));
    m.fingers.push_back(make_finger("finger", k));
    Simulation sim(m);
    const Vec3 p0(-0.0001, 0.001, h - 0.0001 * h / w);   // on the left slope, 0.1 mm from the ridge
    const auto hip = [&](std::size_t, double t) {
      if (t < 0.1) return Vec3(p0 + nL * (0.01 - (0.01 + d) * t / 0.1));
      return Vec3(p0 - d * nL + Vec3(0.003 * std::min((t - 0.1) / 0.3, 1.0), 0.0, 0.0));
    };
    Vec3 go_stuck = Vec3::Constant(kInfinity);
    bool stuck_on_right = false, slipped = false, switched = false;
    graspsim::test::run(sim, 500, hip, [&](const TickRecord& rec) {
      const HapticFingerRecord& hr = rec.haptic[0];
      const FingerState& fs = sim.state().fingers[0];
      if (hr.phase == ContactPhase::kFree) return;
      // The cone at every servo tick, about the stored normal.
      const Vec3 n_w = rec.physics[0].orientation * fs.normal;
      const Vec3& f = rec.servo[0].force;
      const double f_n = f.dot(n_w);
      REQUIRE(f_n >= 0.0);
      REQUIRE((f - f_n * n_w).norm() <= mu * f_n * (1.0 + 1e-12) + 1e-12);
      const Vec3 go = fs.god_object, sp = fs.surface_point;   // body frame, as stored
      const bool on_right = (fs.normal - nR).norm() < 1e-12;
      if (go_stuck.x() == kInfinity) go_stuck = go;   // the first contact tick: the entry point
      if (!slipped) {
        const bool within = (go_stuck - sp).norm() <= mu * hr.depth;
        REQUIRE(within == (hr.phase == ContactPhase::kStick));
        if (within) {
          REQUIRE(go == go_stuck);
          if (on_right) stuck_on_right = true;
        } else {
          slipped = true;
          switched = on_right;   // it broke away at the switch
        }
      }
      // On the surface, within the circle.
      double gap = -kInfinity;
      for (const auto& face : roof.faces) gap = std::max(gap, face.normal.dot(go) - face.offset);
      REQUIRE(gap == Approx(0.0).margin(1e-12));
      REQUIRE((go - sp).norm() <= hr.friction_radius * (1.0 + 1e-9) + 1e-15);
    });
    if (mu > 4.0 / 3.0) {
      CHECK(stuck_on_right);
    } else {
      CHECK(slipped);
      CHECK(switched);
      CHECK_FALSE(stuck_on_right);
    }
  }
}

// Two fingers squeeze an analytic sphere (R = 4 cm, 0.2 kg, mu 0.8) from -x and +x, 6 mm deep
// (twice the m g / (2 mu k) = 3.1 mm needed), and lift it 5 cm in 1 s. Law: the grip holds it
// with no slip; it hangs m g / (2 k) = 2.45 mm below the lift in the tangential springs (to
// 1e-9 m: the critically damped vertical mode, omega = sqrt(2k/m) = 63 rad/s, has decayed by
// e^-63 in the second after the lift; measured 4e-17 m); two_point_grasp sees a grasp along x,
// from the stored contact normals, which oppose. Physics at 500 Hz, as in test_grasp.cpp.
TEST_CASE("two fingers squeeze and lift an analytic sphere", "[finger_contact][sphere][grasp][law]") {
  const double R = 0.04, mass = 0.2, k = 400.0, d = 0.006, lift = 0.05;
  Model m;
  m.rates.physics = 500;
  BodyParams ball;
  ball.name = "ball";
  ball.shape = sphere_shape(R);
  ball.mass = mass;
  ball.inertia = Vec3::Constant(0.4 * mass * R * R);
  ball.material = Material{0.8, kInfinity, kInfinity};
  m.bodies.push_back(ball);
  const double c = std::sqrt(2.0 * k * mass);   // near-critical damping of the vertical mode
  m.fingers.push_back(make_finger("thumb", k, c));
  m.fingers.push_back(make_finger("index", k, c));
  Simulation sim(m);
  double slip = 0.0;
  graspsim::test::run(sim, 3 * m.rates.servo,
                      [&](std::size_t i, double t) {
                        const double z = lift * std::clamp((t - 1.0) / 1.0, 0.0, 1.0);
                        return Vec3(i == 0 ? -(R - d) : (R - d), 0.0, z);
                      },
                      [&](const TickRecord& r) {
                        if (r.haptic_ran) slip += r.haptic[0].slip + r.haptic[1].slip;
                      });
  const BodyState& bs = sim.state().bodies[0];
  const double sag = mass * 9.81 / (2.0 * k);
  CHECK(bs.position.z() == Approx(lift - sag).margin(1e-9));
  CHECK(slip < 1e-6);
  const TwoPointGrasp g = two_point_grasp(sim.model(), sim.state(), 0);
  CHECK(g.held);
  CHECK(std::abs(g.axis.x()) > 0.99);
  // Each normal points from the centre to its HIP, which sits `sag` above it at R - d across:
  // n_0 . n_1 = (sag^2 - (R - d)^2) / (sag^2 + (R - d)^2) = -0.9896 (1e-3: the bounce left).
  const double a2 = (R - d) * (R - d), s2 = sag * sag;
  CHECK(sim.state().fingers[0].normal.dot(sim.state().fingers[1].normal) == Approx((s2 - a2) / (s2 + a2)).margin(1e-3));
}

// The opposing test uses the stored normals, for any shape: two fingers pressing the same side
// of a sphere (normals 30 deg apart) hold nothing; opposite sides (150 deg apart) do.
TEST_CASE("two_point_grasp opposes by the stored contact normals", "[finger_contact][grasp]") {
  const double R = 0.04;
  for (double spread : {M_PI / 6.0, 5.0 * M_PI / 6.0}) {
    Model m;
    m.gravity = Vec3::Zero();
    m.bodies.push_back(graspsim::test::fixed_body("ball", sphere_shape(R), Material{0.8, kInfinity, kInfinity}));
    m.fingers.push_back(make_finger("a", 400.0));
    m.fingers.push_back(make_finger("b", 400.0));
    Simulation sim(m);
    graspsim::test::run(sim, 30, [&](std::size_t i, double) {
      const double a = i == 0 ? 0.0 : spread;
      return Vec3((R - 0.003) * std::cos(a), (R - 0.003) * std::sin(a), 0.0);
    });
    REQUIRE(sim.state().fingers[0].phase != ContactPhase::kFree);
    REQUIRE(sim.state().fingers[1].phase != ContactPhase::kFree);
    CHECK(two_point_grasp(sim.model(), sim.state(), 0).held == (std::cos(spread) < 0.0));
  }
}

// Determinism on a mesh: the same run twice gives bit-identical god-objects and forces (the walk
// iterates faces in a fixed order; nothing depends on addresses or unordered containers).
TEST_CASE("finger contact on a mesh is deterministic", "[finger_contact][determinism]") {
  const auto trace = [] {
    Model m;
    m.gravity = Vec3::Zero();
    BodyParams b;
    b.name = "ball";
    b.shape = graspsim::test::mesh_shape(graspsim::test::icosphere(0.05, 3));
    b.mass = 0.5;
    b.inertia = Vec3::Constant(0.0005);
    b.material = Material{0.5, kInfinity, kInfinity, 0.3, 1.0};
    m.bodies.push_back(b);
    FingerParams f = make_finger("f", 500.0, 2.0);
    f.radius = 0.003;
    m.fingers.push_back(f);
    Simulation sim(m);
    std::vector<double> out;
    graspsim::test::run(sim, 3000, [](std::size_t, double t) {
          const double rho = 0.06 - 0.01 * std::min(t, 1.0);   // in from outside, 3 mm deep
          return Vec3(rho * std::cos(3.0 * t), rho * std::sin(3.0 * t), 0.01 * t);
        },
        [&](const TickRecord& r) {
          out.push_back(r.servo[0].force.x());
          out.push_back(r.haptic[0].god_object.z());
        });
    return out;
  };
  const std::vector<double> a = trace(), b = trace();
  REQUIRE(a.size() == b.size());
  CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
  int touching = 0;   // ticks with a force (even entries), so the contact path ran
  for (std::size_t i = 0; i < a.size(); i += 2) touching += a[i] != 0.0;
  CHECK(touching > 500);
}
