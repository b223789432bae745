// The simulation: a Model, its State, and the fixed order of work inside one servo tick.
#pragma once

#include <cstdint>
#include <vector>

#include "graspsim/engine/collision.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/object_contact.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

class Simulation {
 public:
  // Validates the model (std::invalid_argument naming the field) and starts from its initial state.
  explicit Simulation(Model model);

  // One servo tick, in this order (the only place the order is written):
  //   1 servo    the HIP of every finger from `input`
  //   2 haptic   (tick % (servo/haptic) == 0) friction cone for every finger, in finger order
  //   3 servo    force on every finger, k (GO - HIP) with the newest HIP; its reaction, acting at
  //              the contact point on the surface (GO less the pad radius), is added to the
  //              contacted body's physics window
  //   4 physics  (tick % (servo/physics) == 0): body-body contact wrenches for every pair in
  //              contact, all at the state of this tick; then for every body, in body order: record
  //              the state at this tick; residual F = finger impulse over the window / dt + floor +
  //              other bodies + m g and T likewise; integrate over dt = 1/physics s;
  //              clear the window; flag a body whose state diverged (see record.hpp)
  //   5 tick += 1
  // Time is tick / servo, computed, never accumulated.
  void step(const Input& input, TickRecord& record);

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  const Divisors& divisors() const { return divisors_; }
  std::int64_t tick() const { return state_.tick; }
  double time() const { return static_cast<double>(state_.tick) / model_.rates.servo; }   // s

 private:
  Model model_;
  Divisors divisors_;
  State state_;
  CollisionWorld collision_;
  bool collision_stale_ = false;   // bodies moved since collision_ was last updated
  std::vector<int> scratch_;   // candidate bodies of a finger query
  BodyContacts body_contacts_;            // body-body contact (its own broadphase)
  std::vector<Wrench> contact_wrench_;    // per body: body-body contact wrench of this step
  std::vector<int> contact_points_;       // per body: body-body contact points of this step
  std::vector<double> floor_reach_;       // m, per body: farthest floor point from the centre of mass
  std::vector<std::uint8_t> floor_clear_;  // per body: 1 when none of its floor points is active
};

}  // namespace graspsim
