// The multi-rate scheduler: one integer clock, each loop on its divisor, a fixed order.
#include <catch2/catch.hpp>

#include <stdexcept>

#include "tests/engine/harness.hpp"

using namespace graspsim;

// Each loop runs exactly duration x rate times, on the ticks that are multiples of its
// divisor, starting at tick 0; time is tick / servo (computed, so exact for every tick).
TEST_CASE("each loop runs exactly duration x rate times", "[schedule]") {
  const Rates cases[] = {{3000, 500, 50}, {3000, 3000, 3000}, {1000, 250, 50}, {3000, 1000, 3000}, {600, 600, 10}};
  for (const Rates& rates : cases) {
    Model m;
    m.rates = rates;
    m.bodies.push_back(graspsim::test::make_box("b", 1.0, Vec3(0.1, 0.1, 0.1), Vec3::Zero()));
    m.fingers.push_back(graspsim::test::make_finger("f", 100.0));
    Simulation sim(m);
    const int seconds = 3;
    std::int64_t servo = 0, haptic = 0, physics = 0;
    graspsim::test::run(sim, static_cast<std::int64_t>(seconds) * rates.servo, graspsim::test::no_fingers,
                        [&](const TickRecord& r) {
                          REQUIRE(r.tick == servo);
                          REQUIRE(r.haptic_ran == (r.tick % (rates.servo / rates.haptic) == 0));
                          REQUIRE(r.physics_ran == (r.tick % (rates.servo / rates.physics) == 0));
                          ++servo;
                          haptic += r.haptic_ran;
                          physics += r.physics_ran;
                        });
    INFO(rates.servo << "/" << rates.haptic << "/" << rates.physics);
    CHECK(servo == seconds * rates.servo);
    CHECK(haptic == seconds * rates.haptic);
    CHECK(physics == seconds * rates.physics);
    CHECK(sim.time() == static_cast<double>(seconds));
  }
}

// The order inside a tick is haptic, then servo force, then physics. On tick 0, with the HIP
// already inside a box, the haptic loop makes the contact, so the servo force of that same
// tick is non-zero, and the physics step of that same tick includes its reaction (gravity is
// off). Impulse consistency: that force acts for one servo period, 1/3000 s, of the 1/50 s
// step, so the residual the step applies is -f / 60 (not -f, which would give the body 60
// times the impulse the finger delivered).
TEST_CASE("haptic, servo force and physics run in that order within a tick", "[schedule]") {
  Model m;
  m.gravity = Vec3::Zero();
  m.bodies.push_back(graspsim::test::make_box("b", 1.0, Vec3(0.1, 0.1, 0.1), Vec3::Zero()));
  m.fingers.push_back(graspsim::test::make_finger("f", 100.0));
  Simulation sim(m);
  Input in = make_input(m);
  in.fingers[0].hip = Vec3(0.09, 0.0, 0.0);   // 1 cm inside the +x face
  TickRecord r = make_tick_record(m);
  sim.step(in, r);
  REQUIRE(r.haptic_ran);
  REQUIRE(r.physics_ran);
  REQUIRE(r.haptic[0].phase == ContactPhase::kStick);
  REQUIRE(r.servo[0].force.x() == Approx(100.0 * 0.01).epsilon(1e-12));
  REQUIRE(r.physics[0].force.isApprox(-r.servo[0].force / 60.0, 1e-15));
}

// A rate that does not divide the servo rate is refused, naming the field.
TEST_CASE("a rate that does not divide the servo rate is an error", "[schedule]") {
  Model m;
  m.rates = Rates{3000, 700, 50};
  REQUIRE_THROWS_WITH(Simulation(m), Catch::Contains("rates.haptic") && Catch::Contains("does not divide"));
  m.rates = Rates{3000, 500, 70};
  REQUIRE_THROWS_WITH(Simulation(m), Catch::Contains("rates.physics"));
  m.rates = Rates{3000, 0, 50};
  REQUIRE_THROWS_WITH(Simulation(m), Catch::Contains("rates.haptic"));
}
