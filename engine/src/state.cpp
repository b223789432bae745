// The initial State and the sizing of per-tick records.
#include "graspsim/engine/state.hpp"

#include "graspsim/engine/object_contact.hpp"
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
  const std::size_t n = model.bodies.size();
  s.pairs.resize(n * (n > 0 ? n - 1 : 0) / 2);
  s.fingers.resize(model.fingers.size());
  return s;
}

TickRecord make_tick_record(const Model& model) {
  TickRecord r;
  r.servo.resize(model.fingers.size());
  r.haptic.resize(model.fingers.size());
  r.physics.resize(model.bodies.size());
  // Room for every contact point a step can have, as Simulation reserves its couplings: each
  // body's floor points and kMaxPairPoints per pair of bodies, so that no step allocates.
  const std::size_t n = model.bodies.size();
  std::size_t points = kMaxPairPoints * n * (n > 0 ? n - 1 : 0) / 2;
  if (model.floor.enabled)
    for (const BodyParams& bp : model.bodies) points += static_cast<std::size_t>(floor_point_count(bp.shape));
  r.contacts.reserve(points);
  return r;
}

Input make_input(const Model& model) {
  Input in;
  in.fingers.resize(model.fingers.size());
  return in;
}

}  // namespace graspsim
