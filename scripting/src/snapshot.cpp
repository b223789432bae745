// The view a scenario's scripts see, filled from the simulation.
#include "graspsim/engine/local_model.hpp"
#include "graspsim/engine/simulation.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::scripting {

void fill_snapshot(const Simulation& sim, const TickRecord& last, const std::vector<double>& slip, Snapshot& s) {
  const Model& model = sim.model();
  const State& state = sim.state();
  s.time = sim.time();
  s.local_model = uses_local_model(model);
  s.objects.resize(model.bodies.size());
  for (std::size_t b = 0; b < model.bodies.size(); ++b) {
    const BodyState& bs = state.bodies[b];
    ObjectSnapshot& o = s.objects[b];
    o.name = model.bodies[b].name;
    o.position = bs.position;
    o.orientation = quat_of(bs.rotation);
    o.velocity = bs.velocity;
    o.angular_velocity = bs.angular_velocity;
    o.floor_contacts = last.physics[b].floor_contacts;
  }
  s.fingers.resize(model.fingers.size());
  for (std::size_t f = 0; f < model.fingers.size(); ++f) {
    FingerSnapshot& fs = s.fingers[f];
    fs.name = model.fingers[f].name;
    fs.hip = last.servo[f].hip;
    fs.force = last.servo[f].force;
    fs.god_object = last.haptic[f].god_object;
    const int body = state.fingers[f].body;
    if (body >= 0) fs.touching = model.bodies[body].name;
    else fs.touching = body == kFloor ? "floor" : "";
    fs.phase = state.fingers[f].phase;
    fs.slip = slip[f];
  }
}

}  // namespace graspsim::scripting
