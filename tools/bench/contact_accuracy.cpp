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

// Runs `duration` s of servo ticks; false when a body diverged (the run stops there). The state
// afterwards is the one at t = duration: the last physics step, at tick duration x servo - servo
// / physics, integrates over the final 1/physics s. Counts the physics steps into `steps`.
bool run(Simulation& sim, double duration, long long& steps) {
  const Model& m = sim.model();
  const Input input = make_input(m);
  TickRecord record = make_tick_record(m);
  const std::int64_t ticks = std::llround(duration * m.rates.servo);
  steps = 0;
  for (std::int64_t n = 0; n < ticks; ++n) {
    sim.step(input, record);
    if (record.diverged_body >= 0) return false;
    if (record.physics_ran) ++steps;
  }
  return true;
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
  long long steps = 0;
  r.diverged = !run(sim, setup.duration, steps);
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
  long long steps = 0;
  r.diverged = !run(sim, setup.duration, steps);
  const Vec3 d = sim.state().bodies[0].position - model.bodies[0].position;
  r.slide = d.x();
  r.sideways = std::abs(d.y());
  r.sink = -d.z();
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
  r.diverged = !run(sim, setup.settle_duration, r.steps);
  const BodyState& end = sim.state().bodies[0];
  r.height_error = std::abs(end.position.z() - setup.half);
  r.tilt = std::min({axis_tilt(end.rotation, 0), axis_tilt(end.rotation, 1), axis_tilt(end.rotation, 2)});
  return r;
}

}  // namespace graspsim::bench
