// Free body micro-benchmark (README.md, "Speed targets"): the cost of one physics step of a free
// body (no floor, no fingers, no other body) against a bare Eigen explicit-Euler loop doing the
// same arithmetic with nothing around it. Prints the median over repeats of ns per step for:
//   bare Euler      v += dt F/m, x += dt v, w += dt R (R^T T ./ J), R = (I + S(w) dt) R
//   bare + n-o-a    the same with the paper's n-o-a re-orthonormalisation of R
//   integrate_body  the engine's integrator alone (kNeglect: the paper's update, normalised)
//   Simulation      Simulation::step with servo = haptic = physics, so every step is a physics
//                   step: gravity, the record, the integrator, the divergence check, sleep off
// and the ratio of the last to the first (the target: within 3).
// Not a test (tests never time things): run it by hand, on a quiet machine,
//   ./build/tools/graspsim_free_body [REPEATS]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "graspsim/engine/integrate.hpp"
#include "graspsim/engine/simulation.hpp"

using namespace graspsim;

namespace {

constexpr int kSteps = 200000;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <class F>
double ns_per_step(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  const auto t1 = std::chrono::steady_clock::now();
  return std::chrono::duration<double, std::nano>(t1 - t0).count() / kSteps;
}

Mat3 skew_of(const Vec3& w) {
  Mat3 s;
  s << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return s;
}

volatile double g_sink = 0.0;   // keeps the loops' results alive

// The bare explicit-Euler loop the engine's integrator is compared with: kSteps steps of a free
// body (no torque), with or without the n-o-a re-orthonormalisation after each (a template
// parameter, so neither variant pays a branch).
template <bool kOrthonormalise>
void bare_euler(const BodyParams& body, const Vec3& gravity, double dt) {
  Vec3 x = body.position, v = body.velocity, w = body.angular_velocity;
  Mat3 R = Mat3::Identity();
  const Vec3 F = body.mass * gravity, T = Vec3::Zero();
  for (int i = 0; i < kSteps; ++i) {
    v += dt * F / body.mass;
    x += dt * v;
    w += dt * (R * (R.transpose() * T).cwiseQuotient(body.inertia));
    R = (Mat3::Identity() + skew_of(w) * dt) * R;
    if constexpr (kOrthonormalise) orthonormalize(R);
  }
  g_sink = x.sum() + R.sum() + w.sum();
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 9;
  BodyParams body;
  body.name = "body";
  body.mass = 0.4;
  body.inertia = Vec3(4e-4, 3e-4, 2e-4);
  body.velocity = Vec3(0.1, 0.0, 2.0);
  body.angular_velocity = Vec3(0.3, 2.0, 0.1);
  const double dt = 1.0 / 1000.0;
  const Vec3 gravity(0.0, 0.0, -9.81);

  std::vector<double> bare, bare_noa, integ, sim_ns;
  for (int r = 0; r <= repeats; ++r) {
    const double b = ns_per_step([&] { bare_euler<false>(body, gravity, dt); });
    const double bn = ns_per_step([&] { bare_euler<true>(body, gravity, dt); });
    const double ib = ns_per_step([&] {
      BodyState s;
      s.velocity = body.velocity;
      s.angular_velocity = body.angular_velocity;
      const Vec3 F = body.mass * gravity, T = Vec3::Zero();
      for (int i = 0; i < kSteps; ++i) integrate_body(body, Gyroscopic::kNeglect, s, F, T, dt);
      g_sink = s.position.sum() + s.rotation.sum();
    });
    Model m;
    m.rates = Rates{1000, 1000, 1000};
    m.gravity = gravity;
    m.bodies.push_back(body);
    Simulation sim(m);
    Input input = make_input(m);
    TickRecord record = make_tick_record(m);
    const double sb = ns_per_step([&] {
      for (int i = 0; i < kSteps; ++i) sim.step(input, record);
      g_sink = sim.state().bodies[0].position.sum();
    });
    if (r == 0) continue;   // warm-up
    bare.push_back(b);
    bare_noa.push_back(bn);
    integ.push_back(ib);
    sim_ns.push_back(sb);
  }
  const double base = median(bare);
  std::printf("graspsim_free_body: one free body, %d steps per run, %d repeats (median ns per step)\n", kSteps, repeats);
  std::printf("  %-16s %8.1f ns  %5.2fx\n", "bare Euler", base, 1.0);
  std::printf("  %-16s %8.1f ns  %5.2fx\n", "bare + n-o-a", median(bare_noa), median(bare_noa) / base);
  std::printf("  %-16s %8.1f ns  %5.2fx\n", "integrate_body", median(integ), median(integ) / base);
  std::printf("  %-16s %8.1f ns  %5.2fx\n", "Simulation::step", median(sim_ns), median(sim_ns) / base);
  return 0;
}
