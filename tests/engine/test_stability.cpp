// The stability check's laws (engine/stability.hpp): the one-step map of each scheme against
// closed forms, on bare matrices and on bodies built from a State.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "graspsim/engine/stability.hpp"
#include "tests/engine/harness.hpp"
#include "tests/support/random.hpp"

using namespace graspsim;
using namespace graspsim::test;

namespace {

Eigen::MatrixXd scalar(double x) { return Eigen::MatrixXd::Constant(1, 1, x); }

// A random symmetric positive semi-definite n x n matrix of rank `rank`, scaled by `scale`:
// sum of `rank` outer products of random vectors.
Eigen::MatrixXd random_psd(std::mt19937_64& rng, int n, int rank, double scale) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, n);
  for (int r = 0; r < rank; ++r) {
    Eigen::VectorXd v(n);
    for (int i = 0; i < n; ++i) v[i] = 2.0 * uniform01(rng) - 1.0;
    m += scale * uniform01(rng) * v * v.transpose();
  }
  return m;
}

}  // namespace

// Symplectic Euler on a spring k and mass m (no damper), a = h^2 k / m: the map
// [[1 - a, 1], [-a, 1]] has trace 2 - a and determinant 1, so its eigenvalues are a conjugate
// pair on the unit circle while |2 - a| <= 2 (a <= 4: the radius is exactly 1), and a real pair
// with product 1 beyond, the larger (a - 2) / 2 + sqrt(((a - 2) / 2)^2 - 1). With a damper,
// b = h c / m: trace 2 - a - b, determinant 1 - b, stable iff b < 2 and a < 4 - 2 b.
// Tolerance 1e-9: EigenSolver on a 2 x 2 is accurate to a few ulps, except near a = 4 where the
// two eigenvalues meet at -1 and a double root moves by sqrt(eps) (kept 1e-3 away from it).
TEST_CASE("symplectic Euler on a spring and mass: the map's radius is the closed form", "[stability][law]") {
  const double h = 0.02;   // s: the paper's 50 Hz
  int unstable = 0;
  for (double a = 0.05; a < 12.0; a += 0.05) {
    if (std::abs(a - 4.0) < 1e-3) continue;
    const double k_over_m = a / (h * h);
    const double radius = spectral_radius(one_step_map(Integrator::kPaper, scalar(k_over_m), scalar(0.0), h, 1));
    const double half = 0.5 * (a - 2.0);
    const double expected = a < 4.0 ? 1.0 : half + std::sqrt(half * half - 1.0);
    INFO("h^2 k / m = " << a);
    CHECK(radius == Approx(expected).epsilon(1e-9));
    CHECK(paper_radius_1d(k_over_m, 0.0, h) == Approx(expected).epsilon(1e-12));
    CHECK((radius > kUnstableRadius) == (a > 4.0));
    unstable += radius > kUnstableRadius ? 1 : 0;
  }
  CHECK(unstable > 100);   // the sweep did cross the bound
  // With a damper: the closed form against the map, and the bound b < 2, a < 4 - 2 b.
  for (double b = 0.1; b < 2.5; b += 0.2) {
    for (double a = 0.1; a < 8.0; a += 0.3) {
      if (std::abs(a - (4.0 - 2.0 * b)) < 1e-2 || std::abs(b - 2.0) < 1e-2) continue;
      const double radius = spectral_radius(one_step_map(Integrator::kPaper, scalar(a / (h * h)), scalar(b / h), h, 1));
      INFO("h^2 k / m = " << a << ", h c / m = " << b);
      CHECK(radius == Approx(paper_radius_1d(a / (h * h), b / h, h)).epsilon(1e-9));
      CHECK((radius > kUnstableRadius) == (b > 2.0 || a > 4.0 - 2.0 * b));
    }
  }
}

// The linearly implicit scheme (linearised backward Euler), S y1 = y0 - h^2 K z0 with
// S = I + h C + h^2 K, z1 = z0 + y1: for one spring and damper, a = h^2 k / m and b = h c / m,
// the map [[1 - a / S, 1 / S], [-a / S, 1 / S]] (S = 1 + a + b) has determinant 1 / S and trace
// (2 + b) / S; its eigenvalues are a conjugate pair of modulus 1 / sqrt(1 + a + b) while
// b^2 < 4 a, and real and below 1 otherwise (1 + det - trace = a / S > 0, Jury): the radius is
// below 1 for every a > 0, however stiff the spring or slow the rate. Swept over stiffness
// (1e-2 to 1e12 N/m per kg), damping (0 to 1e6 N s/m per kg) and rate (50 to 3000 Hz), and over
// random 6 x 6 couplings (positive definite K: radius < 1; a K and C sharing a null direction
// leave that direction free: radius 1, the free coasting, to 1e-7 for the rounding of its
// Jordan block).
TEST_CASE("the implicit map's radius is below one for any stiffness, damping and rate", "[stability][law]") {
  for (int order : {1, 2}) {
  for (int rate : {50, 100, 500, 3000}) {
    const double h = 1.0 / rate;
    for (double k = 1e-2; k <= 1e12; k *= 10.0) {
      for (double c : {0.0, 1e-2, 1.0, 1e2, 1e4, 1e6}) {
        const double radius = spectral_radius(one_step_map(Integrator::kImplicit, scalar(k), scalar(c), h, order));
        INFO("order " << order << ", " << rate << " Hz, k/m = " << k << ", c/m = " << c);
        const double a = h * h * k, b = h * c;
        // BDF2 damps a slow mode by O(a^2) (it is second order): under a = 1e-4 that is below
        // the rounding of 1, and the radius rounds to 1 (measured: exactly 1.0 at a = 1e-9).
        if (order == 2 && a < 1e-4) CHECK(radius <= 1.0 + 1e-12);
        else CHECK(radius < 1.0);
        if (order == 1 && b * b < 0.99 * 4.0 * a) CHECK(radius == Approx(1.0 / std::sqrt(1.0 + a + b)).epsilon(1e-9));
      }
    }
  }
  }
  for (int order : {1, 2}) {
  std::mt19937_64 rng(12);
  for (int trial = 0; trial < 200; ++trial) {
    const double h = 1.0 / (50.0 + 2950.0 * uniform01(rng));
    const double scale = std::pow(10.0, 12.0 * uniform01(rng) - 2.0);   // 1/s^2: 1e-2 to 1e10
    const Eigen::MatrixXd k = random_psd(rng, 6, 6, scale) + 1e-3 * scale * Eigen::MatrixXd::Identity(6, 6);
    const Eigen::MatrixXd c = random_psd(rng, 6, 3, std::sqrt(scale));
    INFO("order " << order << ", trial " << trial);
    CHECK(spectral_radius(one_step_map(Integrator::kImplicit, k, c, h, order)) < 1.0);
    // A free direction: K and C both zero along e_0.
    Eigen::MatrixXd k0 = k, c0 = c;
    k0.row(0).setZero();
    k0.col(0).setZero();
    c0.row(0).setZero();
    c0.col(0).setZero();
    CHECK(spectral_radius(one_step_map(Integrator::kImplicit, k0, c0, h, order)) <= 1.0 + 1e-7);
  }
}
}

// BDF2 (implicit_order 2): the map must be the recurrence it claims, stepped by hand for a mass on
// a spring and damper, y = h v: S2 y1 = (4 y0 - y_-1)/3 - (2/3) a (4 z0 - z_-1)/3 with a = h^2 k/m,
// S2 = 1 + (2/3) b + (4/9) a, b = h c/m; z1 = (4 z0 - z_-1)/3 + (2/3) y1. Same operations in
// another order: equal to 1e-12 of the state's scale.
// L-stability: for a stiff undamped spring (a >> 1) the characteristic polynomial
// (1 + 4a/9) r^2 ... has roots of modulus ~ (4a)^(-1/4) = 1/sqrt(2 h w): BDF2 damps the mode out
// as the spring stiffens (measured 0.0231 at a = 1e6 against 0.0224, 0.00714 at 1e8 against
// 0.00707; within 4 % from a = 1e6 on, the next term of the expansion).
TEST_CASE("the BDF2 map steps the BDF2 recurrence", "[stability][law]") {
  for (double a : {1e-4, 1e-1, 1.0, 10.0, 1e4}) {
    for (double b : {0.0, 0.1, 3.0}) {
      const double h = 0.02;
      const Eigen::MatrixXd map = one_step_map(Integrator::kImplicit, scalar(a / (h * h)), scalar(b / h), h, 2);
      REQUIRE(map.rows() == 4);
      double z0 = 0.3, y0 = -0.2, zm = 0.1, ym = 0.05;
      for (int step = 0; step < 5; ++step) {
        Eigen::Vector4d x(z0, y0, zm, ym);
        const Eigen::Vector4d mapped = map * x;
        const double s2 = 1.0 + 2.0 / 3.0 * b + 4.0 / 9.0 * a;
        const double y1 = ((4.0 * y0 - ym) / 3.0 - 2.0 / 3.0 * a * (4.0 * z0 - zm) / 3.0) / s2;
        const double z1 = (4.0 * z0 - zm) / 3.0 + 2.0 / 3.0 * y1;
        INFO("a " << a << ", b " << b << ", step " << step);
        CHECK(mapped[0] == Approx(z1).margin(1e-12));
        CHECK(mapped[1] == Approx(y1).margin(1e-12));
        CHECK(mapped[2] == Approx(z0).margin(1e-12));
        CHECK(mapped[3] == Approx(y0).margin(1e-12));
        zm = z0, ym = y0, z0 = z1, y0 = y1;
      }
    }
  }
  const double h = 0.02;
  for (double a : {1e6, 1e8, 1e10, 1e12}) {
    INFO("a " << a);
    const double radius = spectral_radius(one_step_map(Integrator::kImplicit, scalar(a / (h * h)), scalar(0.0), h, 2));
    CHECK(radius == Approx(std::pow(4.0 * a, -0.25)).epsilon(0.04));
  }
}

namespace {

// A box (half sizes a, b, c along x, y, z) at the origin, pinched along x by two fingers
// sticking at the centres of its x faces: a State built by hand, as the haptic stage leaves it.
struct Pinch {
  Model model;
  State state;
};

Pinch pinch(double k, double c, int physics, const Vec3& half, double mass) {
  Pinch p;
  p.model.rates.physics = physics;
  p.model.bodies.push_back(make_box("box", mass, half, Vec3::Zero()));
  p.model.fingers.push_back(make_finger("thumb", k, c));
  p.model.fingers.push_back(make_finger("index", k, c));
  p.state = initial_state(p.model);
  for (int f = 0; f < 2; ++f) {
    const double side = f == 0 ? -1.0 : 1.0;
    FingerState& fs = p.state.fingers[f];
    fs.phase = ContactPhase::kStick;
    fs.body = 0;
    fs.god_object = Vec3(side * half.x(), 0.0, 0.0);
    fs.surface_point = fs.god_object;
    fs.normal = Vec3(side, 0.0, 0.0);
    fs.friction_radius = 1e-3;
  }
  return p;
}

}  // namespace

// A box pinched along x by two sticking fingers (k, c each) at its centre height: each finger is
// an isotropic spring at (+-a, 0, 0), so translation and rotation decouple. Translations:
// K = 2 k, M = m. Pitch about y and yaw about z: the points move +-a theta across the axis,
// K = 2 k a^2, C = 2 c a^2, over I_y = m (a^2 + c_z^2) / 3 and I_z = m (a^2 + b^2) / 3; roll about
// x moves neither point (radius 1, free). The map's radius is the largest of the single modes'
// closed forms (paper_radius_1d, checked above), to 1e-6 (the 12 x 12 EigenSolver, with the free
// roll's Jordan block). The box is flatter in z than in y, so pitch is the stiffest mode and the
// check names it. Swept over the pad stiffness and two physics rates. Under the gimbal rule the
// rotation about the grasp axis is the rule's, removed from the map: the free roll's eigenvalue
// 1 goes with it, and a stable grasp's radius is its springs' alone, below 1.
TEST_CASE("a box pinched by two fingers: the radius is that of its stiffest single mode", "[stability][law]") {
  const Vec3 half(0.03, 0.03, 0.02);
  const double m = 0.2, c = 2.0;
  const double i_y = m * (half.x() * half.x() + half.z() * half.z()) / 3.0;
  const double i_z = m * (half.x() * half.x() + half.y() * half.y()) / 3.0;
  int flagged = 0, passed = 0;
  for (int physics : {50, 100}) {
    const double h = 1.0 / physics;
    for (double k : {100.0, 200.0, 400.0, 800.0, 1600.0}) {
      const double a2 = half.x() * half.x();
      const double springs = std::max({paper_radius_1d(2.0 * k / m, 2.0 * c / m, h),
                                       paper_radius_1d(2.0 * k * a2 / i_y, 2.0 * c * a2 / i_y, h),
                                       paper_radius_1d(2.0 * k * a2 / i_z, 2.0 * c * a2 / i_z, h)});
      for (bool gimbal : {false, true}) {
        const double expected = gimbal ? springs : std::max(springs, 1.0);   // the free roll, or not
        Pinch p = pinch(k, c, physics, half, m);
        if (gimbal) {
          p.model.grasp.torsion = Torsion::kGimbal;
          p.model.grasp.gimbal_finger = 0;
          p.model.grasp.critical_area = 1e-9;   // the pads' circles (pi 1e-6 m^2) are larger: locked
        }
        StabilityCheck check(p.model);
        const StabilityReport r = check.analyse(p.state);
        REQUIRE(r.worst == 0);
        const StabilityMode& mode = r.groups[0];
        INFO(physics << " Hz, k = " << k << " N/m, gimbal rule " << gimbal << ": " << r.warning(p.model));
        CHECK(mode.radius == Approx(expected).epsilon(1e-6));
        CHECK(r.unstable() == (expected > kUnstableRadius));
        if (r.unstable()) {
          CHECK(mode.motion.find("pitch about y") == 0);
          CHECK(mode.springs == std::vector<std::string>{"finger 'thumb'", "finger 'index'"});
          // The rate it names is stable and the one below it (a divisor of 3000 Hz that is a
          // multiple of the rate) is not.
          REQUIRE(mode.stable_physics > physics);
          CHECK(check.analyse(p.state, mode.stable_physics, Integrator::kPaper).unstable() == false);
          ++flagged;
        } else {
          ++passed;
        }
        CHECK_FALSE(check.analyse(p.state, physics, Integrator::kImplicit).unstable());
      }
    }
  }
  CHECK(flagged > 0);
  CHECK(passed > 0);
}

// The gravity-drop rule with the pads' torsional friction c_t turns a pinched body about the
// grasp axis quasi-statically, w_u = T_u / c_t, so the floor's torque about the axis,
// T_u = -K_u theta, gives theta1 = (1 - h K_u / c_t) theta0: explicit in the angle, unstable for
// h K_u / c_t > 2. A box resting on four corners of floor (k_f per corner, vertical and
// tangential anchors) pinched along x through its centre: K_u = 4 k_f (b^2 + c^2) about x. With
// c_t = h K_u / g the mode's eigenvalue is 1 - g: flagged for g = 2.5 (radius 1.5) and not for
// g = 1.25 (0.25); the other modes (soft floor and pads) are stable at 50 Hz. Tolerance 1e-9:
// the eigenvalue is this formula, computed.
TEST_CASE("the quasi-static grasp turn is flagged when the floor's torque about the axis overshoots",
          "[stability][law]") {
  const Vec3 half(0.04, 0.04, 0.04);
  const double m = 0.4, k_f = 50.0, h = 0.02;
  const double k_u = 4.0 * k_f * (half.y() * half.y() + half.z() * half.z());   // N m/rad
  for (double g : {2.5, 1.25}) {
    Pinch p = pinch(100.0, 1.0, 50, half, m);
    p.model.floor.enabled = true;
    p.model.floor.material = Material{0.8, k_f, 1.0};
    p.model.grasp.torsion = Torsion::kGravityDrop;
    p.model.grasp.critical_area = 1.0;   // m^2: far above the pads' circles, so the body turns
    p.model.grasp.torsional_damping = h * k_u / g;
    for (int v = 0; v < 4; ++v) p.state.bodies[0].floor_contacts[v].active = true;   // the bottom corners
    StabilityCheck check(p.model);
    const StabilityReport r = check.analyse(p.state);
    INFO("h K_u / c_t = " << g << ": " << r.warning(p.model));
    REQUIRE(r.worst == 0);
    CHECK(r.unstable() == (g > 2.0));
    if (r.unstable()) {
      CHECK(r.groups[0].radius == Approx(g - 1.0).epsilon(1e-9));
      CHECK(r.groups[0].motion.find("rotation about the grasp axis of 'box'") == 0);
      CHECK(r.groups[0].springs == std::vector<std::string>{"the floor under 'box'"});
    }
  }
}

// The monitor runs the analysis at its first call and again only when the contact signature
// changes (a pose alone does not), and gives each mode's warning once: the grip that lets go with
// one finger and closes again returns to the mode already warned of.
TEST_CASE("the monitor analyses again only when the contact set changes and warns once per mode",
          "[stability]") {
  Pinch p = pinch(800.0, 2.0, 50, Vec3(0.03, 0.03, 0.02), 0.2);   // pitch: h^2 K / I = 4.4, unstable
  StabilityMonitor monitor(p.model);
  const std::string first = monitor.update(p.state);
  CHECK(first.find("at 50 Hz the paper's explicit step of 'box' on finger 'thumb' and finger 'index'") == 0);
  CHECK(monitor.analyses() == 1);
  p.state.bodies[0].position.x() += 1e-3;   // moved, same contacts
  CHECK(monitor.update(p.state).empty());
  CHECK(monitor.analyses() == 1);
  const FingerState held = p.state.fingers[1];
  p.state.fingers[1].phase = ContactPhase::kFree;   // the index lets go: a new contact set
  p.state.fingers[1].body = kNoBody;
  const std::string one_finger = monitor.update(p.state);
  CHECK(monitor.analyses() == 2);
  CHECK(one_finger.find("on finger 'thumb' has") != std::string::npos);   // a new mode: warned
  p.state.fingers[1] = held;   // and grips again: the first mode, already warned of
  CHECK(monitor.update(p.state).empty());
  CHECK(monitor.analyses() == 3);
  CHECK(monitor.report().unstable());
}

// The model-only estimates before a run bound the paper's explicit step (a box rocking on four
// corner springs: h^2 12 k / m < 4 - 2 h 12 c / m); under the implicit scheme they do not apply
// and say nothing. 10 kN/m per corner under a 0.4 kg box at 50 Hz: h^2 12 k / m = 120.
TEST_CASE("the model's estimates speak for the paper's scheme only", "[stability]") {
  Model m;
  m.floor.enabled = true;
  m.floor.material = Material{0.8, 1e4, 1.0};
  m.bodies.push_back(make_box("box", 0.4, Vec3(0.04, 0.04, 0.04), Vec3(0.0, 0.0, 0.04)));
  const std::vector<std::string> paper = stability_warnings(m);
  REQUIRE(paper.size() == 1);
  CHECK(paper[0].find("object 'box' on the floor") == 0);
  m.integrator = Integrator::kImplicit;
  CHECK(stability_warnings(m).empty());
}
