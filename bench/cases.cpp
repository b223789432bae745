// The hard cases of the work-precision benchmark: see cases.hpp.
#include "bench/cases.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "graspsim/engine/record.hpp"
#include "graspsim/engine/simulation.hpp"

namespace graspsim::bench {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Complete elliptic integral of the first kind, K(k) = pi / (2 AGM(1, sqrt(1 - k^2))), m = k^2.
double elliptic_k(double m) {
  double a = 1.0, b = std::sqrt(1.0 - m);
  for (int i = 0; i < 64 && std::abs(a - b) > 1e-16 * a; ++i) {
    const double an = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = an;
  }
  return kPi / (2.0 * a);
}

// A model whose loops all run at `rate` (no fingers: the servo and haptic loops have nothing to
// do, so the cost measured is the physics stage's).
Model free_model(int rate, Gyroscopic g) {
  Model m;
  m.rates = Rates{rate, rate, rate};
  m.gyroscopic = g;
  return m;
}

// Runs the simulation for `duration` s; after every physics step calls each(state, t) with t the
// time the state belongs to (k steps of dt). Returns false when a body diverged.
template <class Each>
bool run_for(Simulation& sim, double duration, const Input& input, Each&& each) {
  TickRecord record = make_tick_record(sim.model());
  const std::int64_t ticks = std::llround(duration * sim.model().rates.servo);
  const double dt = 1.0 / sim.model().rates.physics;
  std::int64_t steps = 0;
  for (std::int64_t n = 0; n < ticks; ++n) {
    sim.step(input, record);
    if (record.diverged_body >= 0) return false;
    if (record.physics_ran) {
      ++steps;
      if (!each(record, static_cast<double>(steps) * dt)) return true;
    }
  }
  return true;
}

}  // namespace

const char* integrator_name(Gyroscopic g) {
  switch (g) {
    case Gyroscopic::kNeglect: return "neglect";
    case Gyroscopic::kExplicit: return "explicit";
    case Gyroscopic::kImplicit: return "implicit";
  }
  return "?";
}

// ---- a) spin_flip --------------------------------------------------------------------------

double intermediate_axis_period(const Vec3& J, const Vec3& w) {
  if (!(J.x() < J.y() && J.y() < J.z()))
    throw std::invalid_argument("intermediate_axis_period: moments must satisfy J1 < J2 < J3");
  const double m2 = J.cwiseProduct(w).squaredNorm();   // M^2, (kg m^2/s)^2
  const double e2 = w.dot(J.cwiseProduct(w));          // 2E, J
  const double j1 = J.x(), j2 = J.y(), j3 = J.z();
  double wp = 0.0, k2 = 0.0;
  if (m2 > e2 * j2) {   // the body turns about axis 3 side of the separatrix
    wp = std::sqrt((j3 - j2) * (m2 - e2 * j1) / (j1 * j2 * j3));
    k2 = (j2 - j1) * (e2 * j3 - m2) / ((j3 - j2) * (m2 - e2 * j1));
  } else {              // axis 1 side: indices 1 and 3 swapped
    wp = std::sqrt((j2 - j1) * (e2 * j3 - m2) / (j1 * j2 * j3));
    k2 = (j3 - j2) * (m2 - e2 * j1) / ((j2 - j1) * (e2 * j3 - m2));
  }
  if (!(k2 >= 0.0 && k2 < 1.0) || !(wp > 0.0))
    throw std::invalid_argument("intermediate_axis_period: the motion is on the separatrix");
  return 4.0 * elliptic_k(k2) / wp;
}

Model spin_flip_model(int rate, Gyroscopic g, const SpinFlipSetup& setup) {
  Model m = free_model(rate, g);
  m.gravity = Vec3::Zero();
  BodyParams b;
  b.name = "body";
  b.mass = 1.0;
  b.inertia = setup.inertia;
  b.shape = box_shape(Vec3(0.1, 0.1, 0.1));
  b.angular_velocity = setup.spin;   // R = I: body and world frames coincide
  m.bodies.push_back(b);
  return m;
}

SpinFlipResult run_spin_flip(int rate, Gyroscopic g, const SpinFlipSetup& setup) {
  SpinFlipResult r;
  r.period_ref = intermediate_axis_period(setup.inertia, setup.spin);
  const Model model = spin_flip_model(rate, g, setup);
  Simulation sim(model);
  const Input input = make_input(model);
  const Vec3& J = setup.inertia;
  const double e0 = 0.5 * setup.spin.dot(J.cwiseProduct(setup.spin));
  const Vec3 l0 = J.cwiseProduct(setup.spin);
  const Vec3 l_hat = l0.normalized();
  double previous = 1.0, first = -1.0, last = -1.0;   // y . L0 hat; crossing times (s)
  const double dt = 1.0 / rate;
  r.diverged = !run_for(sim, setup.duration, input, [&](const TickRecord&, double t) {
    const BodyState& s = sim.state().bodies[0];
    const Vec3 w_b = s.rotation.transpose() * s.angular_velocity;
    const double e = 0.5 * w_b.dot(J.cwiseProduct(w_b));
    const Vec3 l = s.rotation * J.cwiseProduct(w_b);
    r.energy_drift = std::max(r.energy_drift, std::abs(e - e0) / e0);
    r.energy_gain = std::max(r.energy_gain, (e - e0) / e0);
    r.momentum_drift = std::max(r.momentum_drift, (l - l0).norm() / l0.norm());
    const double c = s.rotation.col(1).dot(l_hat);
    if ((previous >= 0.0) != (c >= 0.0)) {   // a crossing between t - dt and t, interpolated
      const double tc = t - dt + dt * previous / (previous - c);
      if (first < 0.0) first = tc;
      last = tc;
      ++r.crossings;
    }
    previous = c;
    return true;
  });
  if (r.diverged) {
    r.energy_drift = r.momentum_drift = r.energy_gain = INFINITY;
  }
  if (r.crossings >= 2) r.period = 2.0 * (last - first) / (r.crossings - 1);
  return r;
}

// ---- b) gyro_precession --------------------------------------------------------------------

namespace {
struct TopInertia {
  double i1_pivot;   // kg m^2: transverse moment about the pivot
  double i3;         // kg m^2: about the symmetry axis
  double mgl;        // N m
};
TopInertia top_inertia(const PrecessionSetup& s) {
  const Vec3 j = box_inertia(s.mass, s.half_extents);
  const double l = s.lever();
  return {j.x() + s.mass * l * l, j.z(), s.mass * 9.81 * l};
}
Vec3 top_axis(const PrecessionSetup& s) {   // world, at t = 0: body z turned by tilt about x
  return Vec3(0.0, -std::sin(s.tilt), std::cos(s.tilt));
}
}  // namespace

double steady_precession_rate(const PrecessionSetup& s) {
  const TopInertia t = top_inertia(s);
  const double a = t.i1_pivot * std::cos(s.tilt), b = t.i3 * s.spin;
  const double disc = b * b - 4.0 * a * t.mgl;
  if (disc < 0.0) throw std::invalid_argument("steady_precession_rate: spin too slow for steady precession");
  return (b - std::sqrt(disc)) / (2.0 * a);
}

double fast_top_precession_rate(const PrecessionSetup& s) {
  const TopInertia t = top_inertia(s);
  return t.mgl / (t.i3 * s.spin);
}

Vec3 precession_pivot(const PrecessionSetup& s) {
  // The HIP sits inside the box, under the bottom face's centre (the origin) by the spring's
  // static compression along the axis, m g cos(tilt) / k, so the spring starts carrying the normal
  // part of the weight.
  return top_axis(s) * (s.mass * 9.81 * std::cos(s.tilt) / s.stiffness);
}

Model precession_model(int rate, Gyroscopic g, const PrecessionSetup& s) {
  Model m;
  m.rates = Rates{3000, 500, rate};   // the paper's servo and haptic loops
  m.gyroscopic = g;
  const Vec3 axis = top_axis(s);
  const double omega = steady_precession_rate(s);
  BodyParams b;
  b.name = "top";
  b.shape = box_shape(s.half_extents);
  b.mass = s.mass;
  b.inertia = box_inertia(s.mass, s.half_extents);
  b.material.mu = s.mu;
  b.position = axis * s.lever();   // the bottom face's centre at the origin
  b.orientation = Quat(Eigen::AngleAxisd(s.tilt, Vec3::UnitX()));
  // Steady precession: w = w3 axis + W z (so w . axis = spin + W cos(tilt): the spin is set as
  // the total along the axis, the w3 of the formula), and the centre circles the vertical through
  // the pivot at W.
  b.angular_velocity = (s.spin - omega * std::cos(s.tilt)) * axis + omega * Vec3::UnitZ();
  b.velocity = omega * Vec3::UnitZ().cross(b.position);
  m.bodies.push_back(b);
  FingerParams f;
  f.name = "pivot";
  f.stiffness = s.stiffness;
  f.damping = s.damping;
  m.fingers.push_back(f);
  return m;
}

PrecessionResult run_precession(int rate, Gyroscopic g, const PrecessionSetup& s) {
  PrecessionResult r;
  r.rate_ref = steady_precession_rate(s);
  const Model model = precession_model(rate, g, s);
  Simulation sim(model);
  Input input = make_input(model);
  input.fingers[0].hip = precession_pivot(s);
  // Least squares of the unwrapped azimuth phi(t) = atan2(a_y, a_x) of the axis a on t.
  double sum_t = 0.0, sum_p = 0.0, sum_tt = 0.0, sum_tp = 0.0, n = 0.0;
  const Vec3 a0 = top_axis(s);
  double previous = std::atan2(a0.y(), a0.x()), unwrapped = previous;
  r.diverged = !run_for(sim, s.duration, input, [&](const TickRecord& rec, double t) {
    if (rec.haptic_ran && rec.haptic[0].phase == ContactPhase::kFree) r.lost_contact = true;
    const Vec3 a = sim.state().bodies[0].rotation.col(2);
    const double phi = std::atan2(a.y(), a.x());
    double d = phi - previous;
    while (d > kPi) d -= 2.0 * kPi;
    while (d < -kPi) d += 2.0 * kPi;
    unwrapped += d;
    previous = phi;
    sum_t += t; sum_p += unwrapped; sum_tt += t * t; sum_tp += t * unwrapped; n += 1.0;
    r.max_tilt_change = std::max(r.max_tilt_change, std::abs(std::acos(std::clamp(a.z(), -1.0, 1.0)) - s.tilt));
    return !r.lost_contact;
  });
  r.rate = (n * sum_tp - sum_t * sum_p) / (n * sum_tt - sum_t * sum_t);
  if (r.diverged || !std::isfinite(r.rate)) r.rate = NAN;
  return r;
}

// ---- c) corner_drop ------------------------------------------------------------------------

Quat corner_down(double tip) {
  // Body diagonal vertical: 45 degrees about x, then atan(1/sqrt 2) about y; then tipped about
  // (1, 2, 0) so that it does not balance on the corner (as scenarios/corner_drop.lua).
  return Quat(Eigen::AngleAxisd(tip, Vec3(1.0, 2.0, 0.0).normalized())) *
         Quat(Eigen::AngleAxisd(std::atan(1.0 / std::sqrt(2.0)), Vec3::UnitY())) *
         Quat(Eigen::AngleAxisd(kPi / 4.0, Vec3::UnitX()));
}
double lowest_corner(const Mat3& R, double half) {
  double z = INFINITY;
  for (int i = 0; i < 8; ++i) {
    const Vec3 v(i & 1 ? half : -half, i & 2 ? half : -half, i & 4 ? half : -half);
    z = std::min(z, (R * v).z());
  }
  return z;
}

Model corner_drop_model(int rate, Gyroscopic g, double stiffness, const CornerDropSetup& s) {
  Model m = free_model(rate, g);
  m.floor.enabled = true;
  m.floor.material = Material{s.mu, stiffness, s.damping};
  BodyParams b;
  b.name = "cube";
  const Vec3 half(s.half, s.half, s.half);
  b.shape = box_shape(half);
  b.mass = s.mass;
  b.inertia = box_inertia(s.mass, half);
  b.material.mu = s.mu;
  b.orientation = corner_down(s.tip);
  b.position = Vec3(0.0, 0.0, s.drop - lowest_corner(b.orientation.toRotationMatrix(), s.half));
  m.bodies.push_back(b);
  return m;
}

CornerDropResult run_corner_drop(int rate, Gyroscopic g, double k, const CornerDropSetup& s,
                                 std::vector<Vec3>* samples) {
  CornerDropResult r;
  const Model model = corner_drop_model(rate, g, k, s);
  Simulation sim(model);
  const Input input = make_input(model);
  const double grav = -model.gravity.z();
  const Vec3 J = model.bodies[0].inertia;
  const auto energy = [&](const BodyState& b) {
    const Vec3 w_b = b.rotation.transpose() * b.angular_velocity;
    double e = 0.5 * s.mass * b.velocity.squaredNorm() + 0.5 * w_b.dot(J.cwiseProduct(w_b)) +
               s.mass * grav * b.position.z();
    for (int i = 0; i < 8; ++i) {
      const Vec3 v(i & 1 ? s.half : -s.half, i & 2 ? s.half : -s.half, i & 4 ? s.half : -s.half);
      const double depth = -(b.position + b.rotation * v).z();
      if (depth > 0.0) e += 0.5 * k * depth * depth;
    }
    return e;
  };
  const double e0 = energy(sim.state().bodies[0]);
  r.bound = s.mass * grav * s.drop;
  const std::int64_t every = rate / 50;   // physics steps per 1/50 s
  std::int64_t step = 0;
  if (samples) {
    samples->clear();
    samples->reserve(static_cast<std::size_t>(s.duration * 50.0) + 2);
  }
  r.diverged = !run_for(sim, s.duration, input, [&](const TickRecord& rec, double) {
    if (samples && step++ % every == 0) samples->push_back(rec.physics[0].position);
    const double e = energy(sim.state().bodies[0]);
    r.max_gain = std::max(r.max_gain, std::isfinite(e) ? e - e0 : INFINITY);
    return r.max_gain <= r.bound;   // unstable: no need to run on
  });
  return r;
}

double corner_drop_boundary(int rate, Gyroscopic g, const CornerDropSetup& s, double low,
                            double high, int iterations) {
  if (run_corner_drop(rate, g, high, s).stable()) return high;
  for (int i = 0; i < iterations && high / low > std::exp2(0.125); ++i) {
    const double mid = std::sqrt(low * high);
    if (run_corner_drop(rate, g, mid, s).stable()) low = mid;
    else high = mid;
  }
  return low;
}

double corner_drop_estimate(int rate, const CornerDropSetup& s) {
  const double h = 1.0 / rate;
  return (4.0 - 24.0 * h * s.damping / s.mass) * s.mass / (12.0 * h * h);
}

}  // namespace graspsim::bench
