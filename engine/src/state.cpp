// The initial State and the sizing of per-tick records.
#include "graspsim/engine/state.hpp"

#include <algorithm>
#include <utility>

#include "graspsim/engine/contact_gather.hpp"
#include "graspsim/engine/floor_points.hpp"
#include "graspsim/engine/record.hpp"

namespace graspsim {

State initial_state(const Model& model) {
  State s;
  s.bodies.resize(model.bodies.size());
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const BodyParams& p = model.bodies[i];
    BodyState& b = s.bodies[i];
    b.position = p.position;
    b.rotation = p.orientation.normalized().toRotationMatrix();
    b.velocity = p.velocity;
    b.angular_velocity = p.angular_velocity;
    b.floor_contacts.resize(static_cast<std::size_t>(floor_point_count(p.shape)));
  }
  s.fingers.resize(model.fingers.size());
  // Room for the pairs in contact (the gather's list, swapped with this one each step, has as much).
  s.pairs.reserve(pairs_room(model.bodies.size()));
  return s;
}

const PairContact* find_pair(const State& state, int a, int b) {
  const auto it = std::lower_bound(state.pairs.begin(), state.pairs.end(), std::make_pair(a, b),
                                   [](const PairContact& p, const std::pair<int, int>& k) {
                                     return p.a != k.first ? p.a < k.first : p.b < k.second;
                                   });
  return (it != state.pairs.end() && it->a == a && it->b == b) ? &*it : nullptr;
}

TickRecord make_tick_record(const Model& model) {
  TickRecord r;
  r.servo.resize(model.fingers.size());
  r.haptic.resize(model.fingers.size());
  r.physics.resize(model.bodies.size());
  // Room for the contact points of a step as the physics stages reserve theirs (contact_room); a
  // step with more grows the list once, and none after.
  r.contacts.reserve(contact_room(model));
  return r;
}

Input make_input(const Model& model) {
  Input in;
  in.fingers.resize(model.fingers.size());
  return in;
}

}  // namespace graspsim
