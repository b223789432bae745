// Bodies resting on bodies under the default scheme and the default contact law (no stiffness
// set): towers, pyramids and a pile of 10 cm, 1 kg boxes (bench/scale_scenes.hpp, the scenes the
// benchmark and the peer engines run), placed touching and with gaps, at every physics rate.
//
// The laws (engine/README.md, "Body-body contact"):
//  - passivity: with nothing driven, contact cannot add energy, so the bodies' mechanical energy
//    (kinetic, gravity, and every contact spring) never rises above its start, to rounding;
//  - rest: what stands comes to rest where it was built, less the springs' static set (and the
//    gaps it was built with, which it closes); what falls comes to rest;
//  - nothing is thrown: no box ever rises more than 0.1 mm above where it was built.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "bench/scale_scenes.hpp"
#include "graspsim/engine/contact_gather.hpp"
#include "graspsim/engine/energy.hpp"
#include "tests/engine/harness.hpp"

using namespace graspsim;
namespace scale = graspsim::bench::scale;

namespace {

constexpr double kPi = 3.14159265358979323846;

Model scene(scale::Layout layout, int n, double gap, int rate) {
  Model m;
  m.integrator = Integrator::kImplicit;   // the default scheme, as every scenario runs it
  m.rates.physics = rate;
  m.gravity = Vec3(0.0, 0.0, -scale::kGravity);
  m.floor.enabled = true;
  m.floor.material.mu = scale::kMu;
  const Vec3 half = Vec3::Constant(0.5 * scale::kSide);
  for (const scale::BoxPose& p : scale::layout_boxes(layout, n, gap)) {
    BodyParams b = test::make_box("box" + std::to_string(m.bodies.size()), scale::kMass, half, Vec3(p.x, p.y, p.z));
    b.orientation = Quat(Eigen::AngleAxisd(p.yaw, Vec3::UnitZ()));
    b.material.mu = scale::kMu;   // stiffness and damping unset: the default law
    m.bodies.push_back(b);
  }
  return m;
}

struct Outcome {
  double start = 0.0;           // J: mechanical energy at the start
  double rise = 0.0;            // J: most it rose above the start, at any physics step
  double rounding = 0.0;        // J: what rounding allows that rise
  double end_speed = 0.0;       // m/s: fastest point of any box at the end (|v| + |w| r)
  double highest = -1.0;        // m: most any box rose above where it was built
  std::vector<Vec3> built, end; // m: each box's centre as built and at the end
  bool diverged = false;
};

Outcome settle(const Model& model, double seconds) {
  Simulation sim(model);
  ContactGather gather(sim.model());
  Outcome out;
  for (const BodyParams& b : model.bodies) out.built.push_back(b.position);
  // Rounding: E is a sum over n bodies and their springs of terms up to m g z (about 60 J for
  // the top of a tower of 64), each good to a few eps, and the step's own sums carry as much;
  // 1e-9 (|E0| + 1 J) is far above that (1e-13 of E0 for n = 210) and far below the gains the
  // scheme is held against (0.1 J for a tower of four at 50 Hz, where a box 1 mm up is 0.01 J).
  out.start = mechanical_energy(sim.model(), sim.state(), gather);
  out.rounding = 1e-9 * (std::abs(out.start) + 1.0);
  const auto ticks = static_cast<std::int64_t>(std::llround(seconds * model.rates.servo));
  Input input = make_input(sim.model());
  TickRecord record = make_tick_record(sim.model());
  for (std::int64_t t = 0; t < ticks; ++t) {
    sim.step(input, record);
    if (!record.physics_ran) continue;
    if (record.diverged_body >= 0) {
      out.diverged = true;
      break;
    }
    out.rise = std::max(out.rise, mechanical_energy(sim.model(), sim.state(), gather) - out.start);
    for (std::size_t b = 0; b < out.built.size(); ++b) {
      out.highest = std::max(out.highest, sim.state().bodies[b].position.z() - out.built[b].z());
    }
  }
  const double reach = 0.5 * std::sqrt(3.0) * scale::kSide;   // m: a corner from the centre
  for (const BodyState& b : sim.state().bodies) {
    out.end.push_back(b.position);
    out.end_speed = std::max(out.end_speed, b.velocity.norm() + b.angular_velocity.norm() * reach);
  }
  return out;
}

// The default law's stiffness per point (model.hpp, with_default_law): k = m (4 pi f)^2 with m
// the mass the contact moves, a box's on the floor and half of it between two boxes.
double default_stiffness(double mass, int rate) {
  const double w = 4.0 * kPi * rate;   // rad/s
  return mass * w * w;
}

// A tower's static set: the face between box i - 1 and box i (the floor's for i = 0) carries the
// n - i boxes above it on four corner points, each spring pressed by (n - i) m g / (4 k); box j
// sits lower by the sum over the faces under it, and by the j gaps it was built above the box
// under it. (25 mm at the top of a tower of 64 at 50 Hz, 0.007 mm at 3 kHz.)
std::vector<double> tower_set(int n, double gap, int rate) {
  const double weight = scale::kMass * scale::kGravity;   // N
  std::vector<double> set(n);
  double sunk = 0.0;
  for (int i = 0; i < n; ++i) {
    const double k = default_stiffness(i == 0 ? scale::kMass : 0.5 * scale::kMass, rate);
    sunk += (n - i) * weight / (4.0 * k) + (i == 0 ? 0.0 : gap);
    set[i] = sunk;
  }
  return set;
}

// A pyramid's static set, bounded: the boxes of row r (counted from the top, r = 1..R) carry the
// r (r + 1) / 2 boxes at and above it on 2 r half faces of four points each below them (the
// floor's four points for the base), so the springs under row r are pressed by about
// (r + 1) m g / (16 k) on average; the load is not shared evenly (the middle carries more), so the
// bound doubles it. Box rows sink by the sum under them, and by the gaps below.
double pyramid_set_bound(int rows, double gap, int rate) {
  const double weight = scale::kMass * scale::kGravity;   // N
  const double k_pair = default_stiffness(0.5 * scale::kMass, rate);
  const double k_floor = default_stiffness(scale::kMass, rate);
  double sunk = 2.0 * rows * (rows + 1) / 2.0 * weight / (4.0 * rows * k_floor);
  for (int r = 1; r < rows; ++r) sunk += 2.0 * (r + 1) * weight / (16.0 * k_pair) + gap;
  return sunk;
}

// Passivity, rest and nothing thrown, the same for every scene.
void check_laws(const Outcome& o, double rest_speed) {
  INFO("E0 = " << o.start << " J, rose " << o.rise << " J (rounding " << o.rounding << " J), end speed "
               << o.end_speed << " m/s, highest rise " << o.highest << " m");
  REQUIRE_FALSE(o.diverged);
  CHECK(o.rise <= o.rounding);
  CHECK(o.end_speed <= rest_speed);
  // Thrown: a box higher than it was built by more than 0.1 mm. Energy from nowhere is what
  // throws one (the old scheme's towers threw boxes metres); a box built with gaps may rise by
  // micrometres as it lands on one edge first and tips level (2 um measured in a pyramid of 10
  // rows at 500 Hz), and the passivity check above bounds what it may gain.
  CHECK(o.highest <= 1e-4);
}

// At rest: every point of every box under 1 mm/s.
constexpr double kAtRest = 1e-3;   // m/s
// Where built: within 1 mm of the built position less the static set (the measure).
constexpr double kWhereBuilt = 1e-3;   // m

// Seconds a scene gets: long enough that the 1 mm gaps close and the pile lands and stops
// (measured: the pile of 100 is under 1e-6 m/s by 3 s at every rate), short enough at 3 kHz.
double seconds_for(scale::Layout layout, int rate) {
  if (layout == scale::Layout::kPile) return 3.5;
  return rate >= 3000 ? 0.5 : 1.5;
}

}  // namespace

TEST_CASE("towers of 2 to 64 boxes stand where built and never gain energy, touching or with gaps",
          "[resting][hard][law]") {
  const int rate = GENERATE(50, 500, 3000);
  const int n = GENERATE(2, 4, 8, 16, 32, 64);
  const double gap = GENERATE(0.0, 1e-3);
  CAPTURE(rate, n, gap);
  const Outcome o = settle(scene(scale::Layout::kTower, n, gap, rate), seconds_for(scale::Layout::kTower, rate));
  check_laws(o, kAtRest);
  const std::vector<double> set = tower_set(n, gap, rate);
  for (int i = 0; i < n; ++i) {
    const Vec3 expected = o.built[i] - Vec3(0.0, 0.0, set[i]);
    INFO("box " << i << " at " << o.end[i].transpose() << ", expected " << expected.transpose());
    CHECK((o.end[i] - expected).norm() <= kWhereBuilt);
  }
}

TEST_CASE("pyramids of 5 to 20 rows stand where built and never gain energy, touching or with gaps",
          "[resting][hard][law]") {
  const int rate = GENERATE(50, 500, 3000);
  const int rows = GENERATE(5, 10, 20);
  const double gap = GENERATE(0.0, 1e-3);
  CAPTURE(rate, rows, gap);
  const int n = rows * (rows + 1) / 2;
  const Outcome o = settle(scene(scale::Layout::kPyramid, n, gap, rate), seconds_for(scale::Layout::kPyramid, rate));
  check_laws(o, kAtRest);
  const double set = pyramid_set_bound(rows, gap, rate);
  for (int i = 0; i < n; ++i) {
    const Vec3 moved = o.end[i] - o.built[i];
    INFO("box " << i << " moved " << moved.transpose() << " m; the set is at most " << set << " m");
    CHECK(std::hypot(moved.x(), moved.y()) <= kWhereBuilt);
    CHECK(moved.z() <= 0.0);
    CHECK(-moved.z() <= set + kWhereBuilt);
  }
}

TEST_CASE("a pile of 100 dropped boxes comes to rest, gains no energy and throws nothing", "[resting][hard][law]") {
  const int rate = GENERATE(50, 500, 3000);
  CAPTURE(rate);
  const Outcome o = settle(scene(scale::Layout::kPile, 100, 0.0, rate), seconds_for(scale::Layout::kPile, rate));
  check_laws(o, kAtRest);
  // Nothing thrown sideways either: a box dropped on its column lands and topples, at most a few
  // box sizes away (the columns are 18 cm apart); 0.5 m is a box thrown, not a box fallen.
  double farthest = 0.0;
  for (std::size_t i = 0; i < o.end.size(); ++i) {
    farthest = std::max(farthest, std::hypot(o.end[i].x() - o.built[i].x(), o.end[i].y() - o.built[i].y()));
  }
  CHECK(farthest <= 0.5);
}

TEST_CASE("the checks can fail: a step that gains energy, and boxes pushed up", "[resting][law]") {
  SECTION("the paper's explicit step on springs too stiff for it gains energy, and the check sees it") {
    // A tower of 4 under the paper scheme with k = 2e4 N/m, c = 1 N s/m per point: four points
    // between two 1 kg boxes (reduced mass 0.5 kg) make h^2 4 k / m_r = 64 at 50 Hz, far past the
    // explicit step's limit of 4: its bounce grows every step.
    Model model = scene(scale::Layout::kTower, 4, 0.0, 50);
    model.integrator = Integrator::kPaper;
    model.floor.material = Material{scale::kMu, 2e4, 1.0};
    for (BodyParams& b : model.bodies) b.material = Material{scale::kMu, 2e4, 1.0};
    const Outcome o = settle(model, 0.5);
    CHECK(o.rise > 1e3 * o.rounding);
  }
  SECTION("a tower built 2 mm into itself is pushed apart, and the boxes rise") {
    // Springs pressed 2 mm beyond their set hold 4 x 1/2 k d^2 = 1.6 J a face (k = 0.5 (4 pi
    // 50)^2 N/m); they lift the boxes as they relax. Counted with the springs, the energy still
    // does not rise; the boxes' height does.
    const Outcome o = settle(scene(scale::Layout::kTower, 4, -2e-3, 50), 0.5);
    CHECK(o.rise <= o.rounding);
    CHECK(o.highest > 1e-4);
  }
}
