// Sleep (engine/README.md, "Sleep"): a body whose speeds stay under the thresholds for
// ceil(time x physics) physics steps stops being stepped, pose frozen and velocities zero, and
// wakes when a finger touches it or a moving body reaches it.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "graspsim/engine/state_hash.hpp"
#include "tests/engine/harness.hpp"
#include "bench/mesh_grasp_scene.hpp"

using namespace graspsim;

namespace {

constexpr double kStiffness = 100.0;   // N/m per vertex: stable at 50 Hz (test_floor.cpp)
constexpr double kDamping = 1.0;       // N s/m per vertex
constexpr double kMass = 0.4;          // kg
constexpr double kHalf = 0.04;         // m

struct Pose {
  Vec3 position;
  Mat3 rotation;
};

// A cube resting on the floor at its penalty equilibrium, m g = 4 k d; a second one at x = 0.3 m.
Model resting_boxes(int physics, double sleep_time, bool sleep = true) {
  Model m;
  m.rates.physics = physics;
  m.sleep.enabled = sleep;
  m.sleep.time = sleep_time;
  m.floor.enabled = true;
  m.floor.material = Material{0.8, kStiffness, kDamping};
  const double sag = kMass * 9.81 / (4.0 * kStiffness);
  for (int i = 0; i < 2; ++i) {
    m.bodies.push_back(graspsim::test::make_box(i == 0 ? "box" : "other", kMass, Vec3::Constant(kHalf),
                                                Vec3(0.3 * i, 0.0, kHalf - sag), Material{0.8, kInfinity, kInfinity}));
  }
  return m;
}

// The physics step (counted from 1) at which body b is first asleep, or -1.
int steps_to_sleep(Simulation& sim, int b, int max_steps) {
  Input input = make_input(sim.model());
  TickRecord record = make_tick_record(sim.model());
  for (int step = 0; step < max_steps;) {
    sim.step(input, record);
    if (!record.physics_ran) continue;
    ++step;
    if (sim.state().bodies[b].asleep) return step;
  }
  return -1;
}

}  // namespace

// The rule: a body at rest (here at its equilibrium, speeds ~1e-17) is still after every step, so
// it falls asleep at exactly step N = ceil(time x physics), not one step earlier or later.
// Swept over the rate and the time; exact (an integer count).
TEST_CASE("a body at rest falls asleep after ceil(time x physics) physics steps", "[sleep][law]") {
  for (int physics : {50, 250, 1000}) {
    for (double time : {0.02, 0.1, 0.5, 1.0}) {
      Simulation sim(resting_boxes(physics, time));
      const int expected = static_cast<int>(std::ceil(time * physics));
      INFO("physics " << physics << " Hz, sleep.time " << time << " s: N = " << expected);
      CHECK(steps_to_sleep(sim, 0, expected + 10) == expected);
      CHECK(sim.state().bodies[0].velocity == Vec3::Zero());
      CHECK(sim.state().bodies[0].angular_velocity == Vec3::Zero());
    }
  }
  // Off: never.
  Simulation off(resting_boxes(50, 0.1, false));
  CHECK(steps_to_sleep(off, 0, 200) == -1);
}

// A moving body does not sleep: the box dropped 1 cm falls faster than the threshold within one
// step (g h = 0.2 m/s at 50 Hz), bounces and settles; it sleeps only once the damped bounce
// (slowest mode decaying as exp(-zeta w t), t ~ 1 s) has been under 1 mm/s for 0.5 s.
TEST_CASE("a dropped body sleeps only after it has settled", "[sleep]") {
  Model m = resting_boxes(50, 0.5);
  m.bodies[0].position.z() += 0.01;
  Simulation sim(m);
  Input input = make_input(m);
  TickRecord record = make_tick_record(m);
  int step = 0, asleep_at = -1;
  double last_speed = 0.0;   // m/s: speed at the step before it slept
  while (step < 500 && asleep_at < 0) {
    sim.step(input, record);
    if (!record.physics_ran) continue;
    ++step;
    const BodyState& b = sim.state().bodies[0];
    if (b.asleep) asleep_at = step;
    else last_speed = b.velocity.norm();
  }
  REQUIRE(asleep_at > 25);   // not before the 0.5 s of stillness
  CHECK(last_speed <= m.sleep.linear_speed);
  // Where it sleeps: the equilibrium depth to within how far a mode under 1 mm/s is from its rest.
  const double d = kMass * 9.81 / (4.0 * kStiffness);
  CHECK(sim.state().bodies[0].position.z() == Approx(kHalf - d).margin(1e-3));
}

// Asleep, nothing moves it: position and rotation are bit-identical from tick to tick (== on
// doubles), and so is the state's hash apart from the tick.
TEST_CASE("a sleeping body's pose is bit-identical across ticks", "[sleep][law]") {
  Simulation sim(resting_boxes(50, 0.1));
  REQUIRE(steps_to_sleep(sim, 0, 20) == 5);
  const Vec3 p = sim.state().bodies[0].position;
  const Mat3 R = sim.state().bodies[0].rotation;
  Input input = make_input(sim.model());
  TickRecord record = make_tick_record(sim.model());
  for (int n = 0; n < 3000 * 5; ++n) {
    sim.step(input, record);
    if (!record.physics_ran) continue;
    REQUIRE(sim.state().bodies[0].asleep);
    REQUIRE(sim.state().bodies[0].position == p);
    REQUIRE(sim.state().bodies[0].rotation == R);
    REQUIRE(record.physics[0].position == p);
    REQUIRE(record.physics[0].velocity == Vec3::Zero());
    REQUIRE(record.physics[0].floor_contacts == 4);
  }
}

// A finger touches the sleeping box: it wakes at the first physics step at or after the haptic
// tick of the contact (the finger's force, summed in its window, acts at that step), and moves.
// The other box, untouched, sleeps on.
TEST_CASE("a sleeping body wakes when a finger touches it", "[sleep][law]") {
  Model m = resting_boxes(50, 0.1);
  m.fingers.push_back(graspsim::test::make_finger("index", 400.0, 2.0));
  Simulation sim(m);
  Input input = make_input(m);
  TickRecord record = make_tick_record(m);
  std::int64_t touched = -1, woke = -1;
  for (int n = 0; n < 3000 * 2; ++n) {
    // From 7 cm at -x, towards the face (at -4 cm) from t = 0.5 s at 5 cm/s: contact at 1.1 s.
    const double t = sim.time();
    input.fingers[0].hip = Vec3(-0.07 + 0.05 * std::max(0.0, t - 0.5), 0.0, 0.035);
    const bool was_asleep = sim.state().bodies[0].asleep;
    sim.step(input, record);
    if (record.haptic_ran && record.haptic[0].body == 0 && touched < 0) touched = record.tick;
    if (was_asleep && !sim.state().bodies[0].asleep) woke = record.tick;
    if (touched < 0) {
      REQUIRE(woke < 0);   // nothing wakes it before the touch
    }
  }
  REQUIRE(touched > 0);
  // The first physics tick at or after the touch (every 60 servo ticks at 3000 / 50 Hz).
  CHECK(woke == (touched + 59) / 60 * 60);
  CHECK(sim.state().bodies[0].position.x() > 0.001);   // pushed along +x
  CHECK(sim.state().bodies[1].asleep);
}

// A body landing on a sleeping one wakes it: the falling box's bounding box reaches the sleeper's
// (FCL's broadphase) while it moves, at the latest at the step of first contact. Woken, the lower
// box carries the new load: it sinks to the equilibrium of both weights on its four floor
// springs, (m_a + m_b) g = 4 k d, within 1 mm (the stack keeps rocking a little at this
// stiffness, so its settling is not what is tested here).
TEST_CASE("a sleeping body wakes when a moving body lands on it", "[sleep][law]") {
  Model m = resting_boxes(500, 0.1);
  // The lower box stays rigid (its floor contact is the floor's 100 N/m per vertex, at rest from
  // the start); the upper one is soft, which makes the pair 2000 N/m per point. It falls from
  // 8 cm above the lower box's top, sqrt(2 h / g) = 0.13 s: the lower one sleeps after 0.1 s.
  m.bodies[1].material = Material{0.8, 2000.0, 10.0};
  m.bodies[1].position = Vec3(0.005, 0.0, 0.2);
  m.bodies[1].mass = 0.1;
  m.bodies[1].inertia = box_inertia(0.1, Vec3::Constant(kHalf));
  Simulation sim(m);
  Input input = make_input(m);
  TickRecord record = make_tick_record(m);
  std::int64_t asleep_at = -1, woke = -1, contact = -1;
  for (int n = 0; n < 3000 * 4; ++n) {
    const bool was_asleep = sim.state().bodies[0].asleep;
    sim.step(input, record);
    if (!record.physics_ran) continue;
    if (!was_asleep && sim.state().bodies[0].asleep && asleep_at < 0) asleep_at = record.tick;
    if (was_asleep && !sim.state().bodies[0].asleep && woke < 0) woke = record.tick;
    if (record.physics[1].body_contacts > 0 && contact < 0) contact = record.tick;
  }
  REQUIRE(asleep_at > 0);
  REQUIRE(contact > asleep_at);   // it landed on a sleeping box
  REQUIRE(woke > 0);
  CHECK(woke <= contact);
  const double d = (kMass + 0.1) * 9.81 / (4.0 * kStiffness);   // m: 12.3 mm, against 9.8 mm alone
  CHECK(sim.state().bodies[0].position.z() == Approx(kHalf - d).margin(1e-3));
}

// Sleep is in the State: the hash differs between a run with and without it once the box sleeps,
// two runs with sleep hash the same at every physics tick (deterministic).
TEST_CASE("sleep is part of the state and deterministic", "[sleep][determinism]") {
  Simulation a(resting_boxes(50, 0.1)), b(resting_boxes(50, 0.1)), off(resting_boxes(50, 0.1, false));
  Input input = make_input(a.model());
  TickRecord record = make_tick_record(a.model());
  bool differs = false;
  for (int n = 0; n < 3000; ++n) {
    a.step(input, record);
    b.step(input, record);
    off.step(input, record);
    if (!record.physics_ran) continue;
    REQUIRE(state_hash(a.state()) == state_hash(b.state()));
    differs = differs || state_hash(a.state()) != state_hash(off.state());
  }
  CHECK(differs);
}

// Sleep changes a run only while a body sleeps, and then only by how far the awake body would have
// crept: a run's outcome with sleep equals the one without within that.
//  - The profile's scene (bench/mesh_grasp_scene.hpp): the pebble starts at rest (speeds
//    ~1e-16), sleeps from 0.5 s until the fingers touch it at 1.4 s, is lifted 3 cm and held.
//    Awake, it creeps by ~1e-16 m/s x 1 s: the two final poses agree to 1e-9 m and 1e-9 rad
//    (rounding grown through 2.6 s of grasp; 1/30,000,000 of the lift).
//  - A box dropped 1 cm, which sleeps once its bounce is under 1 mm/s, then is pushed 2 cm along
//    the floor by a finger. Frozen at |v| <= v_th, its pose is within v_th / w of where the
//    damped rest converges (w = sqrt(4 k / m) = 32 rad/s: 3e-5 m); the push then carries that
//    offset along. Tolerance 1e-4 m, three times it.
TEST_CASE("a scenario's outcome with sleep equals the one without it", "[sleep][law]") {
  SECTION("the profile's three-finger mesh grasp") {
    Pose end[2];
    for (int s = 0; s < 2; ++s) {
      Model m = graspsim::bench::mesh_grasp_model();
      m.sleep.enabled = s == 1;
      Simulation sim(m);
      Input input = make_input(m);
      TickRecord record = make_tick_record(m);
      bool slept = false;
      for (int n = 0; n < static_cast<int>(graspsim::bench::kSceneDuration * m.rates.servo); ++n) {
        graspsim::bench::mesh_grasp_hips(sim.time(), input);
        sim.step(input, record);
        slept = slept || sim.state().bodies[0].asleep;
      }
      CHECK(slept == (s == 1));
      end[s] = Pose{sim.state().bodies[0].position, sim.state().bodies[0].rotation};
    }
    CHECK(end[0].position.z() > graspsim::bench::kPebbleRest + 0.02);   // lifted
    CHECK((end[1].position - end[0].position).norm() < 1e-9);
    CHECK((end[1].rotation - end[0].rotation).norm() < 1e-9);
  }
  SECTION("a dropped box, then pushed") {
    Pose end[2];
    for (int s = 0; s < 2; ++s) {
      Model m = resting_boxes(50, 0.5, s == 1);
      m.bodies[0].position.z() += 0.01;
      m.fingers.push_back(graspsim::test::make_finger("index", 400.0, 2.0));
      Simulation sim(m);
      bool slept = false;
      // From 7 cm at -x from t = 3 s at 2 cm/s: contact at 4.5 s, pushed until 6.5 s, then still.
      graspsim::test::run(sim, 3000 * 8, [](std::size_t, double t) {
        return Vec3(-0.07 + 0.02 * std::clamp(t - 3.0, 0.0, 3.5), 0.0, 0.03);
      }, [&](const TickRecord&) { slept = slept || sim.state().bodies[0].asleep; });
      CHECK(slept == (s == 1));
      end[s] = Pose{sim.state().bodies[0].position, sim.state().bodies[0].rotation};
    }
    CHECK(end[0].position.x() > 0.015);   // pushed about 2 cm
    CHECK((end[1].position - end[0].position).norm() < 1e-4);   // measured 1.3e-6 m
  }
}

// A sleeper wakes when its support goes, even when nothing that moves is fast enough to wake
// it: a 2 cm box asleep on a 4 cm box, the lower one pushed out from under it by a finger at
// 2 cm/s (below this scene's 5 cm/s sleep threshold, so its motion alone wakes nothing). The
// pair loses its last contact point when the lower box has moved 3 cm (half widths 2 + 1 cm);
// the upper box wakes at that physics step and falls 4 cm onto the floor, resting with its
// centre at its half width (implicit default contact: sinks micrometres; 1 mm allowed for the
// landing's tilt). Left asleep, it would hang in the air at 5 cm for ever.
TEST_CASE("a sleeping body wakes when its support goes from under it", "[sleep][law]") {
  Model m;
  m.integrator = Integrator::kImplicit;
  m.rates = Rates{3000, 500, 50};
  m.sleep.enabled = true;
  m.sleep.time = 0.2;
  m.sleep.linear_speed = 0.05;
  m.floor.enabled = true;
  m.floor.material = Material{0.3, kInfinity, kInfinity};
  m.bodies.push_back(graspsim::test::make_box("lower", 0.2, Vec3::Constant(0.02), Vec3(0.0, 0.0, 0.02),
                                              Material{0.3, kInfinity, kInfinity}));
  m.bodies.push_back(graspsim::test::make_box("upper", 0.05, Vec3::Constant(0.01), Vec3(0.0, 0.0, 0.05),
                                              Material{0.3, kInfinity, kInfinity}));
  m.fingers.push_back(graspsim::test::make_finger("index", 400.0, 2.0));
  Simulation sim(m);
  Input input = make_input(m);
  TickRecord record = make_tick_record(m);
  bool both_asleep = false;
  std::int64_t lost = -1, woke = -1;
  for (int n = 0; n < 3000 * 4; ++n) {
    // From 3 cm at -x towards the lower box's face (at -2 cm) from t = 0.6 s at 2 cm/s, 1 cm up.
    const double t = sim.time();
    input.fingers[0].hip = Vec3(-0.03 + 0.02 * std::max(0.0, t - 0.6), 0.0, 0.01);
    const bool was_asleep = sim.state().bodies[1].asleep;
    const bool had_contact = find_pair(sim.state(), 0, 1) != nullptr;
    sim.step(input, record);
    if (!record.physics_ran) continue;
    if (t < 0.6 && sim.state().bodies[0].asleep && sim.state().bodies[1].asleep) both_asleep = true;
    if (had_contact && find_pair(sim.state(), 0, 1) == nullptr && lost < 0) lost = record.tick;
    if (was_asleep && !sim.state().bodies[1].asleep && woke < 0) woke = record.tick;
  }
  REQUIRE(both_asleep);
  REQUIRE(lost > 0);
  CHECK(woke == lost);
  CHECK(sim.state().bodies[0].position.x() > 0.03);
  CHECK(sim.state().bodies[1].position.z() == Approx(0.01).margin(1e-3));
}
