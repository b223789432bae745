// The local model of a body between physics steps (engine/local_model.hpp): the pose the fast
// loops see is the screw motion of the body's last twist, and a hand that carries a body at the
// body's own velocity feels a steady force instead of the paper's staircase.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "graspsim/engine/local_model.hpp"
#include "tests/engine/harness.hpp"

using namespace graspsim;

namespace {

Model implicit_model(int physics, bool local_model) {
  Model m;
  m.integrator = Integrator::kImplicit;
  m.local_model = local_model;
  m.rates = Rates{3000, 500, physics};
  m.gravity = Vec3::Zero();
  m.floor.enabled = false;
  return m;
}

}  // namespace

// A constant twist (w, v at the centre of mass) is a screw: the body turns by w tau about the
// line through c = p + w x v / |w|^2 (the points whose velocity is along w) and slides along w by
// (v . w/|w|) tau. So every material point x goes to c + exp(S(w) tau) (x - c) + (v . w^) w^ tau:
// the closed form the model must give, up to rounding (1e-12 m on 10 cm lever arms and 20 ms).
// Swept over the turn per step, from 1e-6 rad (the series branch) to 1 rad, and over tau.
TEST_CASE("local model: the fast loops see the body's screw motion", "[local_model][law]") {
  const Model m = implicit_model(50, true);
  const double w_norm = GENERATE(5e-5, 0.3, 9.0, 50.0);   // rad/s: 1e-6 to 1 rad in a 20 ms step
  const Vec3 axis = Vec3(0.2, -0.5, 1.0).normalized();
  BodyState bs;
  bs.position = Vec3(0.1, -0.2, 0.3);
  bs.rotation = Eigen::AngleAxisd(0.7, Vec3(1.0, 1.0, 0.0).normalized()).toRotationMatrix();
  bs.angular_velocity = w_norm * axis;
  const Vec3 c = bs.position + Vec3(0.0, 0.08, -0.03);   // m: a point of the screw axis
  const double pitch_speed = 0.04;                        // m/s along the axis
  bs.velocity = bs.angular_velocity.cross(bs.position - c) + pitch_speed * axis;
  bs.stepped_at = 600;
  const Vec3 x_body(0.03, -0.02, 0.05);   // m: a material point, body frame
  for (std::int64_t ticks : {1, 7, 30, 60}) {
    const double tau = static_cast<double>(ticks) / 3000.0;
    const Pose pose = fast_loop_pose(m, bs, bs.stepped_at + ticks);
    const Mat3 turn = Eigen::AngleAxisd(w_norm * tau, axis).toRotationMatrix();
    const Vec3 x0 = bs.rotation * x_body + bs.position;
    const Vec3 expected = c + turn * (x0 - c) + pitch_speed * tau * axis;
    CHECK((pose.rotation * x_body + pose.position - expected).norm() < 1e-12);
    CHECK((pose.rotation - turn * bs.rotation).norm() < 1e-12);
    CHECK((pose.velocity - turn * bs.velocity).norm() < 1e-12);
    // The points of the screw's axis stay on it: a rod swung about a grasp axis keeps its
    // fingers' points still (a straight step of the centre would move c by (w tau)^2 |p - c| / 2).
    const Vec3 c_body = bs.rotation.transpose() * (c - bs.position);
    CHECK((pose.rotation * c_body + pose.position - (c + pitch_speed * tau * axis)).norm() < 1e-12);
  }
}

// Off, under the paper's step, asleep or never stepped, the fast loops see the physics pose, bit
// for bit (the paper's traces and the goldens depend on it).
TEST_CASE("local model: off, under the paper's step, the fast loops see the last pose", "[local_model]") {
  BodyState bs;
  bs.position = Vec3(0.1, 0.2, 0.3);
  bs.velocity = Vec3(1.0, -2.0, 0.5);
  bs.angular_velocity = Vec3(3.0, 0.0, -1.0);
  bs.stepped_at = 60;
  Model off = implicit_model(50, false);
  Model paper = implicit_model(50, true);
  paper.integrator = Integrator::kPaper;
  for (const Model* m : {&off, &paper}) {
    const Pose pose = fast_loop_pose(*m, bs, 90);
    CHECK(pose.position == bs.position);
    CHECK(pose.rotation == bs.rotation);
    CHECK(pose.velocity == bs.velocity);
  }
  const Model on = implicit_model(50, true);
  bs.asleep = true;
  CHECK(fast_loop_pose(on, bs, 90).position == bs.position);
  bs.asleep = false;
  bs.stepped_at = -1;
  CHECK(fast_loop_pose(on, bs, 90).position == bs.position);
  CHECK(fast_loop_lead(off) == 0.0);
  // The window's mean tau: servo ticks 1 .. D after a step, D = 60 at 3000 / 50 Hz: 61 / 6000 s.
  CHECK(fast_loop_lead(on) == Approx(61.0 / 6000.0).epsilon(1e-15));
}

// A finger pressed into the -x face of a heavy box that slides along y at v, its HIP carried
// along y at the same v (a hand carrying the body). The GO sticks to the box, so the force
// along y is k (GO_y - HIP_y). Seen with the paper's staircase, the GO stands still for a physics
// period while the HIP moves on, then jumps by v h: a sawtooth of peak-to-peak
// k v (D - 1) / servo (the HIP's travel over the D - 1 servo ticks between jumps). Seen through
// the local model the GO moves with the HIP at every servo tick: the force is steady. The box
// (1000 kg, pushed by about 2 N) changes its speed by 2e-6 of v in a physics period, so the
// model's ripple is that small times k v h: below 1e-3 of the staircase's. Each is measured
// within one physics period (the largest over 0.2 s), so that the box's slow drift under the
// staircase's mean lag, k v h / 2, stays out of it. Swept over the physics rate; the sawtooth
// matches its law within 1e-3 (the box's speed change over a period).
TEST_CASE("local model: a hand carrying a body at its velocity feels a steady force", "[local_model][law]") {
  const int physics = GENERATE(50, 100, 500);
  const double k = 400.0, v = 0.1;   // N/m, m/s
  double ripple[2] = {0.0, 0.0};     // N: largest peak-to-peak of the force along y within a
                                     //    physics period, staircase and model
  for (int on = 0; on < 2; ++on) {
    Model m = implicit_model(physics, on == 1);
    m.bodies.push_back(test::make_box("box", 1000.0, Vec3(0.05, 0.05, 0.05), Vec3::Zero(),
                                      Material{1.0, kInfinity, kInfinity}));
    m.bodies[0].velocity = Vec3(0.0, v, 0.0);
    m.fingers.push_back(test::make_finger("finger", k));
    Simulation sim(m);
    double lo = kInfinity, hi = -kInfinity;   // N: over the current physics period
    test::run(
        sim, 3000 * 3 / 10,
        [&](std::size_t, double t) { return Vec3(t < 0.01 ? -0.06 : -0.045, v * t, 0.0); },
        [&](const TickRecord& r) {
          if (sim.time() < 0.1) return;
          lo = std::min(lo, r.servo[0].force.y());
          hi = std::max(hi, r.servo[0].force.y());
          if (r.physics_ran) {   // the period's last servo tick: its sawtooth is complete
            ripple[on] = std::max(ripple[on], hi - lo);
            lo = kInfinity;
            hi = -kInfinity;
          }
        });
    REQUIRE(sim.state().fingers[0].body == 0);
  }
  const double d = 3000.0 / physics;
  CHECK(ripple[0] == Approx(k * v * (d - 1.0) / 3000.0).epsilon(1e-3));
  CHECK(ripple[1] < 1e-3 * ripple[0]);
}
