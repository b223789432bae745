// Per-body bookkeeping of a physics step (body_step.hpp).
#include "graspsim/engine/body_step.hpp"

#include <cmath>

namespace graspsim {

namespace {
// Whether any finger is in contact with body b.
bool held_by_finger(const State& state, int b) {
  for (const FingerState& fs : state.fingers) {
    if (fs.body == b) return true;
  }
  return false;
}
}  // namespace

BodyRecord& record_body_state(const State& state, int b, int floor_points, int body_points, TickRecord& record) {
  const BodyState& bs = state.bodies[b];
  BodyRecord& rec = record.physics[b];
  rec.position = bs.position;
  rec.orientation = quat_of(bs.rotation);
  rec.velocity = bs.velocity;
  rec.angular_velocity = bs.angular_velocity;
  rec.floor_contacts = floor_points;
  rec.body_contacts = body_points;
  rec.grasp_area = 0.0;
  rec.torsion = 0.0;
  rec.twist = 0.0;
  return rec;
}

void record_sleeping_body(const State& state, int b, int body_points, TickRecord& record) {
  // Nothing to do: its pose stays as it is, bit for bit.
  const BodyState& bs = state.bodies[b];
  BodyRecord& rec = record.physics[b];
  rec = BodyRecord{};
  rec.position = bs.position;
  rec.orientation = quat_of(bs.rotation);
  int touching = 0;
  for (const VertexContact& vc : bs.floor_contacts) touching += vc.active ? 1 : 0;
  rec.floor_contacts = touching;
  rec.body_contacts = body_points;
}

void mark_stepped(BodyState& bs, std::int64_t tick) {
  bs.position_before_step = bs.position;
  bs.rotation_before_step = bs.rotation;
  bs.stepped_at = tick;
}

void finish_body_step(const Model& model, State& state, int b, TickRecord& record) {
  BodyState& bs = state.bodies[b];
  bs.window_force.setZero();
  bs.window_torque.setZero();
  const bool sane = bs.position.allFinite() && bs.rotation.allFinite() &&
                    bs.velocity.squaredNorm() <= kDivergedSpeed * kDivergedSpeed &&
                    bs.angular_velocity.squaredNorm() <= kDivergedAngularSpeed * kDivergedAngularSpeed;
  if (!sane && record.diverged_body < 0) record.diverged_body = b;
  if (!model.sleep.enabled) return;
  // Still when both speeds are under their thresholds after the step; asleep after sleep_steps
  // such steps in a row, with its velocities zeroed.
  const int sleep_steps = static_cast<int>(std::ceil(model.sleep.time * model.rates.physics));
  const bool still = bs.velocity.norm() <= model.sleep.linear_speed && bs.angular_velocity.norm() <= model.sleep.angular_speed;
  bs.still_steps = still ? bs.still_steps + 1 : 0;
  if (bs.still_steps >= sleep_steps && !held_by_finger(state, b)) {
    bs.asleep = true;
    bs.still_steps = 0;
    bs.velocity.setZero();
    bs.angular_velocity.setZero();
  }
}

}  // namespace graspsim
