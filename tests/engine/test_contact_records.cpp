// TickRecord::contacts: every floor and body-body point of a physics step with the force the step
// applied there, under both integrators, checked against the statics of a settled stack.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>

#include "graspsim/engine/record.hpp"
#include "graspsim/engine/simulation.hpp"
#include "graspsim/engine/state_hash.hpp"
#include "tests/engine/harness.hpp"

using namespace graspsim;
using graspsim::test::make_box;

namespace {

constexpr double kG = 9.81;   // m/s^2

// A flat 8 x 8 x 2 cm box of 0.2 kg on a 16 x 16 x 4 cm box of 0.4 kg on the floor, placed at
// its penalty equilibrium (as tests/engine/test_stack.cpp's stack, stable at 50 Hz).
Model stack(Integrator integrator) {
  Model m;
  m.rates.physics = 50;
  m.integrator = integrator;
  m.floor.enabled = true;
  const double bottom = 0.4, top = 0.2, k = 50.0, k_floor = 250.0 * (bottom + top);   // kg, kg, N/m, N/m
  m.floor.material = Material{0.8, k_floor, k_floor / 100.0};
  const Vec3 hb(0.08, 0.08, 0.02), ht(0.04, 0.04, 0.01);
  const double zb = hb.z() - (bottom + top) * kG / (4.0 * k_floor);
  const double zt = zb + hb.z() + ht.z() - top * kG / (4.0 * k);
  m.bodies.push_back(make_box("bottom", bottom, hb, Vec3(0.0, 0.0, zb), Material{0.8, kInfinity, kInfinity}));
  m.bodies.push_back(make_box("top", top, ht, Vec3(0.0, 0.0, zt), Material{0.5, k, 0.5}));
  return m;
}

}  // namespace

// Once the stack has settled (2 s), each body is in static equilibrium: the contact forces on it
// balance its weight. So the floor's points, summed, push the whole stack up by (0.4 + 0.2) kg g,
// and the bottom's points on the top push it up by 0.2 kg g (the same rows push the bottom down:
// one row per point, -force on a). A body still moving would be off by m dv/dt; after 2 s it is
// still to far below 1e-6 of its weight (test_stack.cpp: it drifts < 1e-9 m over 5 s), so 1e-6
// relative. The rows are as many as the counts of BodyRecord (the same points), each floor normal
// points up and each pair's goes from the bottom (a = 0) to the top (b = 1).
TEST_CASE("contact records balance a settled stack's weight", "[stack][record]") {
  for (const Integrator integrator : {Integrator::kPaper, Integrator::kImplicit}) {
    const Model m = stack(integrator);
    Simulation sim(m);
    sim.record_contacts(true);
    Input input = make_input(m);
    TickRecord record = make_tick_record(m);
    do sim.step(input, record);
    while (!(record.physics_ran && sim.time() >= 2.0));
    Vec3 floor_force = Vec3::Zero(), pair_force = Vec3::Zero();
    int floor_rows = 0, pair_rows = 0;
    for (const ContactRecord& c : record.contacts) {
      if (c.a == kFloor) {
        CHECK(c.b == 0);
        CHECK(c.normal == Vec3::UnitZ());
        floor_force += c.force;
        ++floor_rows;
      } else {
        CHECK((c.a == 0 && c.b == 1));
        CHECK(c.normal.z() == Approx(1.0).epsilon(1e-12));
        pair_force += c.force;
        ++pair_rows;
      }
    }
    INFO("integrator " << (integrator == Integrator::kPaper ? "paper" : "implicit") << ", floor " << floor_force.transpose()
                       << " N, pair " << pair_force.transpose() << " N");
    CHECK(floor_rows == record.physics[0].floor_contacts);
    CHECK(floor_rows == 4);   // the bottom's four lower corners
    CHECK(pair_rows == record.physics[0].body_contacts);
    CHECK(pair_rows == 4);    // the top's four lower corners on the bottom's face
    CHECK(floor_force.z() == Approx(0.6 * kG).epsilon(1e-6));
    CHECK(pair_force.z() == Approx(0.2 * kG).epsilon(1e-6));
    CHECK(floor_force.head<2>().norm() < 1e-6 * 0.6 * kG);
    CHECK(pair_force.head<2>().norm() < 1e-6 * 0.2 * kG);
  }
}

// Recording the contact points is write-only: the same stack stepped 2 s with the list on and off
// ends in bit-identical states (state_hash over every field's bits), and with it off the list
// stays empty.
TEST_CASE("recording contact points changes no result", "[stack][record]") {
  for (const Integrator integrator : {Integrator::kPaper, Integrator::kImplicit}) {
    std::uint64_t hash[2] = {0, 0};
    for (const bool on : {false, true}) {
      const Model m = stack(integrator);
      Simulation sim(m);
      sim.record_contacts(on);
      Input input = make_input(m);
      TickRecord record = make_tick_record(m);
      std::size_t most = 0;
      while (sim.time() < 2.0) {
        sim.step(input, record);
        most = std::max(most, record.contacts.size());
      }
      CHECK((most > 0) == on);
      hash[on ? 1 : 0] = state_hash(sim.state());
    }
    CHECK(hash[0] == hash[1]);
  }
}
