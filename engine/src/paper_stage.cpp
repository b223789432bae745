// The paper's explicit physics stage (paper_stage.hpp).
#include "graspsim/engine/paper_stage.hpp"

#include "graspsim/engine/body_step.hpp"
#include "graspsim/engine/grasp_rules.hpp"
#include "graspsim/engine/integrate.hpp"

namespace graspsim {

PaperStage::PaperStage(const Model& model)
    : pair_wrench_(model.bodies.size()), floor_points_(model.bodies.size()), body_points_(model.bodies.size()) {
  couplings_.reserve(contact_room(model));
}

void PaperStage::step(const Model& model, State& state, ContactGather& contacts, std::int64_t ticks_per_step,
                      double pitch_change, bool record_contacts, TickRecord& record) {
  couplings_.clear();
  contacts.gather(model, state, 0.0, couplings_, floor_points_, body_points_);
  // Body against body first, every pair at the state of this tick (equal and opposite); the
  // gather lists the pairs' points before the floor's.
  std::fill(pair_wrench_.begin(), pair_wrench_.end(), Wrench{});
  add_pair_wrenches(model, state, couplings_, pair_wrench_, record_contacts ? &record.contacts : nullptr);
  std::size_t floor_cursor = 0;
  while (floor_cursor < couplings_.size() && couplings_[floor_cursor].source == Coupling::Source::kBody) ++floor_cursor;
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
    body_step(model, state, static_cast<int>(b), floor_cursor, ticks_per_step, pitch_change, record_contacts, record);
}

// The paper's step of one body (section 3.1): the residual force and torque at the state of this
// tick (fingers' window, floor points, other bodies, gravity), the grasp rules and the dead band,
// then the explicit integration. Its floor points are the couplings from `floor_cursor` on.
void PaperStage::body_step(const Model& model, State& state, int b, std::size_t& floor_cursor,
                           std::int64_t ticks_per_step, double pitch_change, bool record_contacts, TickRecord& record) {
  const BodyParams& bp = model.bodies[b];
  BodyState& bs = state.bodies[b];
  if (bs.asleep) {
    record_sleeping_body(state, b, body_points_[b], record);
    return;
  }
  // Impulse-consistent: the step spans ticks_per_step servo ticks, and each servo tick's force
  // acts for one servo period, so the body gets sum(f) / servo = mean(f) * dt. (Dividing by the
  // ticks actually accumulated would apply tick 0's force for a whole step.)
  const double per_tick = 1.0 / static_cast<double>(ticks_per_step);
  Wrench floor;
  const ContactPair* law = nullptr;
  ContactPair floor_law;
  for (; floor_cursor < couplings_.size() && couplings_[floor_cursor].b == b; ++floor_cursor) {
    const Coupling& c = couplings_[floor_cursor];
    if (law == nullptr) {
      floor_law = floor_pair(model, b);
      law = &floor_law;
    }
    double f_n = c.normal_force;
    Vec3 f_t = c.tangential_force;
    clamp_penalty(*law, c.slipping, c.viscous, f_n, f_t);
    const Vec3 f(f_t.x(), f_t.y(), f_n);
    floor.force += f;
    floor.torque += c.arm.cross(f);
    if (record_contacts) record.contacts.push_back(ContactRecord{kFloor, b, c.point, Vec3::UnitZ(), f});
  }
  floor.force += pair_wrench_[b].force;   // from here on: every object contact
  floor.torque += pair_wrench_[b].torque;
  const Vec3 force = bs.window_force * per_tick + floor.force + bp.mass * model.gravity;
  Vec3 torque = bs.window_torque * per_tick + floor.torque;

  BodyRecord& rec = record_body_state(state, b, floor_points_[b], body_points_[b], record);
  const double dt = 1.0 / model.rates.physics;
  apply_grasp_rules(model, state, b, pitch_change, floor, dt, bs, torque, rec);
  dead_band(model.grasp.dead_band, torque);
  rec.force = force;
  rec.torque = torque;
  mark_stepped(bs, state.tick);
  integrate_body(bp, model.gyroscopic, bs, force, torque, dt);
  finish_body_step(model, state, b, record);
}

void add_pair_wrenches(const Model& model, const State& state, const std::vector<Coupling>& couplings,
                       std::vector<Wrench>& wrenches, std::vector<ContactRecord>* records) {
  for (const Coupling& c : couplings) {
    if (c.source != Coupling::Source::kBody) continue;
    const ContactPair law = body_pair(model, c.a, c.b);
    double f_n = c.normal_force;
    Vec3 f_t = c.tangential_force;
    clamp_penalty(law, c.slipping, c.viscous, f_n, f_t);
    const Vec3 f = f_n * c.normal + f_t;   // N on b; -f on a, at the same point
    const Vec3 ra = c.point - state.bodies[c.a].position;
    wrenches[c.b].force += f;
    wrenches[c.b].torque += c.arm.cross(f);
    wrenches[c.a].force -= f;
    wrenches[c.a].torque -= ra.cross(f);
    if (records != nullptr) records->push_back(ContactRecord{c.a, c.b, c.point, c.normal, f});
  }
}

void apply_grasp_rules(const Model& model, const State& state, int b, double pitch_change, const Wrench& contact,
                       double dt, BodyState& bs, Vec3& torque, BodyRecord& rec) {
  if (model.grasp.torsion == Torsion::kNone) return;
  const TwoPointGrasp grasp = two_point_grasp(model, state, b);
  if (!grasp.held) return;
  rec.grasp_area = grasp.area;
  if (model.grasp.torsion == Torsion::kGravityDrop) {
    rec.torsion = gravity_drop(model, b, grasp, dt, contact.force, contact.torque, bs, torque, rec.twist);
  } else if (grasp.first == model.grasp.gimbal_finger || grasp.second == model.grasp.gimbal_finger) {
    TwoPointGrasp toward_other = grasp;   // u from the gimbal finger to the other one
    if (grasp.second == model.grasp.gimbal_finger) toward_other.axis = -grasp.axis;
    rec.twist = gimbal_twist(model, b, toward_other, pitch_change, bs, torque);
  }
}

}  // namespace graspsim
