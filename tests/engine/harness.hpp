// Small helpers for engine tests: scenes built in C++ and a loop that feeds HIP positions.
#pragma once

#include <functional>
#include <vector>

#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/simulation.hpp"

namespace graspsim::test {

// A box body with its inertia from its shape.
inline BodyParams make_box(const std::string& name, double mass, const Vec3& half_extents,
                           const Vec3& position, const Material& material = {}) {
  BodyParams b;
  b.name = name;
  b.shape = box_shape(half_extents);
  b.mass = mass;
  b.inertia = box_inertia(mass, half_extents);
  b.position = position;
  b.material = material;
  return b;
}

inline FingerParams make_finger(const std::string& name, double stiffness, double damping = 0.0) {
  FingerParams f;
  f.name = name;
  f.stiffness = stiffness;
  f.damping = damping;
  return f;
}

// Runs `ticks` servo ticks; finger i's HIP at time t is hips(i, t); `each` sees every record.
inline void run(Simulation& sim, std::int64_t ticks,
                const std::function<Vec3(std::size_t, double)>& hips,
                const std::function<void(const TickRecord&)>& each = {}) {
  Input input = make_input(sim.model());
  TickRecord record = make_tick_record(sim.model());
  for (std::int64_t n = 0; n < ticks; ++n) {
    const double t = sim.time();
    for (std::size_t i = 0; i < input.fingers.size(); ++i) input.fingers[i].hip = hips(i, t);
    sim.step(input, record);
    if (each) each(record);
  }
}

inline Vec3 no_fingers(std::size_t, double) { return Vec3::Zero(); }

}  // namespace graspsim::test
