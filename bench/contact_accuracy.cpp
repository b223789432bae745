// The contact accuracy scenes of the work-precision benchmark: see contact_accuracy.hpp.
#include "bench/contact_accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "bench/cases.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/simulation.hpp"

namespace graspsim::bench {

namespace {

constexpr double kGravity = 9.81;   // m/s^2

// What every scene measures along its run of the cube (body 0).
struct Track {
  bool diverged = false;
  long long steps = 0;        // physics steps run
  double energy_gain = 0.0;   // J: max over the run of E - E0 (energy_of)
  Vec3 mid{0.0, 0.0, 0.0};    // m: the centre after half the physics steps
};

// J: kinetic (translation and rotation) and gravitational energy, E = 1/2 m v^2 + 1/2 w_b . J w_b
// - m g . p, with w_b = R^T w in the body frame. The contact springs' energy is left out: it is
// never negative, so a step that is passive keeps E <= E0 when the run starts at rest with no
// spring stretched (placed touching, or dropped).
double energy_of(const BodyParams& b, const Vec3& gravity, const BodyState& s) {
  const Vec3 w_b = s.rotation.transpose() * s.angular_velocity;
  return 0.5 * b.mass * s.velocity.squaredNorm() + 0.5 * w_b.dot(b.inertia.cwiseProduct(w_b)) -
         b.mass * gravity.dot(s.position);
}

// Runs `duration` s of servo ticks; stops early when a body diverged. The state afterwards is the
// one at t = duration: the last physics step, at tick duration x servo - servo / physics,
// integrates over the final 1/physics s.
Track run(Simulation& sim, double duration) {
  const Model& m = sim.model();
  const Input input = make_input(m);
  TickRecord record = make_tick_record(m);
  const std::int64_t ticks = std::llround(duration * m.rates.servo);
  const long long half = std::llround(duration * m.rates.physics) / 2;
  const double e0 = energy_of(m.bodies[0], m.gravity, sim.state().bodies[0]);
  Track t;
  for (std::int64_t n = 0; n < ticks; ++n) {
    sim.step(input, record);
    if (record.diverged_body >= 0) {
      t.diverged = true;
      return t;
    }
    if (!record.physics_ran) continue;
    const BodyState& b = sim.state().bodies[0];
    t.energy_gain = std::max(t.energy_gain, energy_of(m.bodies[0], m.gravity, b) - e0);
    if (++t.steps == half) t.mid = b.position;
  }
  return t;
}

// rad: angle of body axis `i` (column of R) from world z, up or down. atan2 of the sine and cosine
// keeps tiny angles exact, where acos of a cosine near 1 loses half the digits.
double axis_tilt(const Mat3& R, int i) {
  return std::atan2(std::hypot(R(0, i), R(1, i)), std::abs(R(2, i)));
}

}  // namespace

const char* scheme_name(Integrator s) {
  return s == Integrator::kPaper ? "paper" : "implicit";
}

Model contact_model(int rate, Integrator s, double slope, const ContactSetup& setup) {
  Model m;
  m.rates = setup.loops_at_physics_rate ? Rates{rate, rate, rate} : Rates{3000, 500, rate};
  m.gravity = kGravity * Vec3(std::sin(slope), 0.0, -std::cos(slope));
  m.floor.enabled = true;
  m.floor.material.mu = 1.0;   // the pair takes the lower mu: the cube's
  m.integrator = s;
  if (s == Integrator::kPaper) {   // else stiffness and damping are left unset: the default rule
    m.floor.material.stiffness = setup.soft_stiffness * setup.mass;
    m.floor.material.damping = setup.soft_damping * setup.mass;
  }
  BodyParams b;
  b.name = "cube";
  const Vec3 half(setup.half, setup.half, setup.half);
  b.shape = box_shape(half);
  b.mass = setup.mass;
  b.inertia = box_inertia(setup.mass, half);
  b.material.mu = setup.mu;
  b.position = Vec3(0.0, 0.0, setup.half);   // bottom corners at depth 0: touching, no force
  m.bodies.push_back(b);
  return m;
}

RestResult run_rest(int rate, Integrator s, const ContactSetup& setup) {
  RestResult r;
  Simulation sim(contact_model(rate, s, 0.0, setup));
  const Track t = run(sim, setup.duration);
  r.diverged = t.diverged;
  r.energy_gain = t.energy_gain;
  const BodyState& b = sim.state().bodies[0];
  r.height_error = std::abs(b.position.z() - setup.half);
  r.tilt = axis_tilt(b.rotation, 2);
  r.speed = b.velocity.norm();
  return r;
}

SlopeResult run_slope(int rate, Integrator s, double slope, const ContactSetup& setup) {
  SlopeResult r;
  const Model model = contact_model(rate, s, slope, setup);
  Simulation sim(model);
  const Track t = run(sim, setup.duration);
  r.diverged = t.diverged;
  r.energy_gain = t.energy_gain;
  const Vec3& end = sim.state().bodies[0].position;
  const Vec3 d = end - model.bodies[0].position;
  r.slide = d.x();
  r.sideways = std::abs(d.y());
  r.sink = -d.z();
  r.late = std::hypot(end.x() - t.mid.x(), end.y() - t.mid.y());
  return r;
}

double analytic_slide(double slope, double mu, double t, double g) {
  const double a = g * (std::sin(slope) - mu * std::cos(slope));   // m/s^2 down the slope
  return a > 0.0 ? 0.5 * a * t * t : 0.0;
}

SettleResult run_settle(int rate, Integrator s, const ContactSetup& setup) {
  SettleResult r;
  Model model = contact_model(rate, s, 0.0, setup);
  BodyParams& b = model.bodies[0];
  b.orientation = corner_down(setup.tip);
  b.position = Vec3(0.0, 0.0, setup.drop - lowest_corner(b.orientation.toRotationMatrix(), setup.half));
  Simulation sim(model);
  const Track t = run(sim, setup.settle_duration);
  r.diverged = t.diverged;
  r.steps = t.steps;
  r.energy_gain = t.energy_gain;
  const BodyState& end = sim.state().bodies[0];
  r.height_error = std::abs(end.position.z() - setup.half);
  r.tilt = std::min({axis_tilt(end.rotation, 0), axis_tilt(end.rotation, 1), axis_tilt(end.rotation, 2)});
  return r;
}

}  // namespace graspsim::bench
