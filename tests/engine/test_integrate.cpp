// Rigid-body integration (paper, section 3.1).
#include <catch2/catch.hpp>

#include <cmath>

#include "graspsim/engine/integrate.hpp"
#include "tests/engine/harness.hpp"

using namespace graspsim;

// Free fall against the engine's own discrete scheme. With F = m g only, each physics step is
//   a = (m g) / m,  v_{k+1} = v_k + a dt,  p_{k+1} = p_k + v_{k+1} dt   (symplectic Euler)
// and the recorded state at step k is (p_k, v_k). Replaying the same operations in the same
// order must give the same bits: tolerance zero. The closed form of that recursion,
//   p_k = p_0 + v_0 t_k + g t_k^2 / 2 + g dt t_k / 2,
// is the analytic free fall plus the scheme's known O(dt) offset; it must hold to rounding.
TEST_CASE("free fall matches the integrator's discrete solution exactly", "[integrate][law]") {
  for (int rate : {50, 500, 3000}) {
    Model m;
    m.rates = Rates{3000, 500, rate};
    m.gravity = Vec3(0.1, -0.2, -9.81);
    BodyParams b = graspsim::test::make_box("ball", 0.37, Vec3(0.02, 0.03, 0.04), Vec3(1.0, 2.0, 3.0));
    b.velocity = Vec3(0.3, -0.2, 1.0);
    m.bodies.push_back(b);
    Simulation sim(m);
    const double dt = 1.0 / rate;
    const Vec3 a = (b.mass * m.gravity) / b.mass;
    Vec3 p = b.position, v = b.velocity;
    std::int64_t steps = 0;
    graspsim::test::run(sim, 3000 * 2, graspsim::test::no_fingers, [&](const TickRecord& r) {
      if (!r.physics_ran) return;
      INFO("rate " << rate << " step " << steps);
      REQUIRE(r.physics[0].position == p);
      REQUIRE(r.physics[0].velocity == v);
      const double t = steps * dt;
      const Vec3 closed = b.position + b.velocity * t + m.gravity * (0.5 * t * t + 0.5 * dt * t);
      REQUIRE((r.physics[0].position - closed).norm() < 1e-12 * (1.0 + closed.norm()));
      v += a * dt;
      p += v * dt;
      ++steps;
    });
    CHECK(steps == 2 * rate);
    CHECK(sim.state().bodies[0].position == p);
  }
}

// The paper's n-o-a re-orthonormalisation keeps R a rotation: after 10^6 updates of a body
// spinning at |w| ~ 2.4 rad/s with dt = 1 ms, R^T R = I and det R = 1 to 1e-12 (each step
// leaves only rounding, ~1e-16, and the normalisation removes it instead of letting it grow).
TEST_CASE("R stays orthonormal after a million updates", "[integrate][law]") {
  BodyParams p;
  p.mass = 1.0;
  p.inertia = Vec3(0.1, 0.2, 0.25);
  BodyState s;
  s.angular_velocity = Vec3(0.3, -1.2, 2.0);
  for (int i = 0; i < 1000000; ++i) integrate_body(p, Gyroscopic::kNeglect, s, Vec3::Zero(), Vec3::Zero(), 1e-3);
  const Mat3& R = s.rotation;
  CHECK((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(std::abs(R.determinant() - 1.0) < 1e-12);
  // And it did rotate (the test would pass trivially for R = I).
  CHECK((R - Mat3::Identity()).norm() > 0.1);
}

// Orientation update with w in the world frame. A body already turned 90 degrees about x,
// spun about world z, must turn about world z: its x axis, (1, 0, 0), moves towards +y by
// w dt to first order. Multiplying the increment on the right (R_old (I + S(w) dt), as the
// paper prints it) would turn it about the body's z, which is world -y here, and move the x
// axis towards +z instead.
TEST_CASE("angular velocity is applied in the world frame", "[integrate][law]") {
  BodyParams p;
  p.inertia = Vec3(1.0, 1.0, 1.0);
  BodyState s;
  s.rotation = Eigen::AngleAxisd(M_PI / 2.0, Vec3::UnitX()).toRotationMatrix();
  s.angular_velocity = Vec3(0.0, 0.0, 1.0);
  const double dt = 1e-3;
  integrate_body(p, Gyroscopic::kNeglect, s, Vec3::Zero(), Vec3::Zero(), dt);
  const Vec3 x_axis = s.rotation.col(0);
  CHECK(x_axis.y() == Approx(dt).epsilon(1e-6));
  CHECK(std::abs(x_axis.z()) < 1e-15);
}

// Euler's equation without the gyroscopic term (the paper's approximation):
// w_dot = R Jp^-1 R^T T. A torque about a body principal axis gives w_dot = T / J about it,
// whatever the orientation; one step from rest gives w = T dt / J, to rounding.
TEST_CASE("torque about a principal axis accelerates at T / J", "[integrate][law]") {
  BodyParams p;
  p.inertia = Vec3(0.2, 0.5, 0.6);
  BodyState s;
  s.rotation = Eigen::AngleAxisd(0.7, Vec3(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const Mat3 R0 = s.rotation;
  for (int axis = 0; axis < 3; ++axis) {
    BodyState t = s;
    const Vec3 torque = R0.col(axis) * 0.3;   // N m, along body axis `axis`, in world
    integrate_body(p, Gyroscopic::kNeglect, t, Vec3::Zero(), torque, 0.01);
    const Vec3 expected = R0.col(axis) * (0.3 * 0.01 / p.inertia[axis]);
    CHECK((t.angular_velocity - expected).norm() < 1e-15);
  }
}
