// The physics stage under integrator = "paper": the paper's explicit step (section 3.1). Every
// contact point's penalty force clamped at the state of this tick, then body by body the residual
// force and torque, the grasp rules (3.2) and the dead band (5), and the explicit integration.
#pragma once

#include <cstdint>
#include <vector>

#include "graspsim/engine/contact_gather.hpp"
#include "graspsim/engine/contact_law.hpp"
#include "graspsim/engine/coupling.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

class PaperStage {
 public:
  explicit PaperStage(const Model& model);

  // One physics step of every body. `ticks_per_step` servo ticks make the step (the finger
  // window's sum is its mean times that); `pitch_change` (rad) is the gimbal finger's since the
  // last step. With `record_contacts`, each contact point and its clamped force goes to
  // record.contacts (pairs first, then floor points body by body).
  void step(const Model& model, State& state, ContactGather& contacts, std::int64_t ticks_per_step,
            double pitch_change, bool record_contacts, TickRecord& record);

  // This step's contact points (the gather's), for the stability check and the energy watch.
  const std::vector<Coupling>& couplings() const { return couplings_; }

 private:
  void body_step(const Model& model, State& state, int b, std::size_t& floor_cursor, std::int64_t ticks_per_step,
                 double pitch_change, bool record_contacts, TickRecord& record);

  std::vector<Coupling> couplings_;
  std::vector<Wrench> pair_wrench_;   // per body: the other bodies' push at the state of this tick
  std::vector<int> floor_points_, body_points_;   // per body: points in contact
};

// Each body pair point of `couplings` (kBody) with the paper's clamp applied, its force added to
// b's wrench and its opposite to a's (both at the point), in the couplings' order; with `records`,
// each also appended there.
void add_pair_wrenches(const Model& model, const State& state, const std::vector<Coupling>& couplings,
                       std::vector<Wrench>& wrenches, std::vector<ContactRecord>* records = nullptr);

// The grasp rules on a body's residual torque (paper, 3.2): gravity drop or gimbal about the axis
// of a two-finger grasp; `contact` is the wrench of the floor and the other bodies. Fills the
// record's grasp fields.
void apply_grasp_rules(const Model& model, const State& state, int b, double pitch_change, const Wrench& contact,
                       double dt, BodyState& bs, Vec3& torque, BodyRecord& rec);

}  // namespace graspsim
