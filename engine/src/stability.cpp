// The stability check's inputs (stability.hpp): the couplings and grasp hinges of a state, the
// contact signature, and the monitor that re-runs the analysis (stability_modes.cpp) when the
// signature changes.
#include "graspsim/engine/stability.hpp"

#include <algorithm>
#include <cmath>

#include "graspsim/engine/contact_law.hpp"
#include "graspsim/engine/finger_contact.hpp"
#include "graspsim/engine/grasp_rules.hpp"

namespace graspsim {
namespace {

std::string quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace

ContactSignature contact_signature(const State& state) {
  ContactSignature s;
  for (const FingerState& fs : state.fingers) {
    s.finger_body.push_back(fs.body);
    s.finger_phase.push_back(static_cast<int>(fs.phase));
  }
  for (const BodyState& bs : state.bodies) {
    int active = 0;
    for (const VertexContact& vc : bs.floor_contacts) active += vc.active ? 1 : 0;
    s.floor_points.push_back(active);
    s.asleep.push_back(bs.asleep ? 1 : 0);
  }
  for (const PairContact& pc : state.pairs) {
    s.pair_points.push_back(pc.a);
    s.pair_points.push_back(pc.b);
    s.pair_points.push_back(pc.count);
  }
  return s;
}

StabilityCheck::StabilityCheck(const Model& model, ContactGather* contacts)
    : model_(model), own_(contacts ? nullptr : std::make_unique<ContactGather>(model_)),
      contacts_(contacts ? contacts : own_.get()) {}

std::string StabilityCheck::name(const Coupling& c) const {
  switch (c.source) {
    case Coupling::Source::kFinger: return "finger " + quoted(model_.fingers[c.slot].name);
    case Coupling::Source::kFloor: return "the floor under " + quoted(model_.bodies[c.b].name);
    case Coupling::Source::kBody:
      return "the contact of " + quoted(model_.bodies[c.a].name) + " and " + quoted(model_.bodies[c.b].name);
  }
  return "?";
}

std::vector<Coupling> StabilityCheck::couplings(const State& state) {
  std::vector<Coupling> out;
  // Fingers: the servo force k (GO - HIP) + c (v_GO - v_HIP), with the GO riding on the body, is
  // a spring from a point fixed in the world (the HIP) to the body's material point under the GO.
  // The paper's scheme applies the mean of the window's servo forces, each computed at the pose
  // (and velocity) the body has had since the last physics step, since a body only moves at
  // physics steps: over the map the finger acts as an explicit spring at the physics rate; the
  // window changes nothing but which HIP it pulls towards (an input, not a state).
  for (std::size_t f = 0; f < state.fingers.size(); ++f) {
    const FingerState& fs = state.fingers[f];
    if (fs.phase == ContactPhase::kFree || fs.body < 0) continue;
    const BodyState& bs = state.bodies[fs.body];
    const ContactPair pair = finger_contact_pair(model_, static_cast<int>(f), fs.body);
    Coupling c;
    c.source = Coupling::Source::kFinger;
    c.b = fs.body;
    c.slot = static_cast<int>(f);
    c.normal = bs.rotation * fs.normal;
    c.point = bs.rotation * fs.god_object + bs.position - model_.fingers[f].radius * c.normal;
    c.arm = c.point - bs.position;
    c.k_n = c.k_t = pair.stiffness;
    c.c_n = c.c_t = model_.fingers[f].damping;
    c.slipping = fs.phase == ContactPhase::kSlip;
    out.push_back(c);
  }
  // Floor points that touched at the last step and the points of the pairs that did, at the pose
  // now, with the law the step uses (the implicit scheme's defaults filled in).
  const std::size_t fingers = out.size();
  contacts_->last_contacts(model_, state, out);
  out.erase(std::remove_if(out.begin() + static_cast<std::ptrdiff_t>(fingers), out.end(),
                           [](const Coupling& c) { return !(std::isfinite(c.k_n) && std::isfinite(c.c_n)); }),
            out.end());
  return out;
}

std::vector<GraspHinge> StabilityCheck::hinges(const State& state) const {
  std::vector<GraspHinge> out;
  const GraspParams& gp = model_.grasp;
  if (gp.torsion == Torsion::kNone) return out;
  for (std::size_t b = 0; b < state.bodies.size(); ++b) {
    const TwoPointGrasp grasp = two_point_grasp(model_, state, static_cast<int>(b));
    if (!grasp.held) continue;
    GraspHinge h;
    h.body = static_cast<int>(b);
    h.point = grasp.go_first;
    h.axis = grasp.axis;
    if (gp.torsion == Torsion::kGravityDrop) {
      // Below A_crit the rules turn the body about the axis by the gravity-drop torque and the
      // floor's (and other bodies') torque about it; above, they hold the rate at zero.
      if (grasp.area < gp.critical_area) {
        h.rate = gp.torsional_damping > 0.0 ? GraspHinge::Rate::kQuasiStatic : GraspHinge::Rate::kInertial;
      }
    } else if (!(grasp.area > gp.critical_area) ||
               (grasp.first != gp.gimbal_finger && grasp.second != gp.gimbal_finger)) {
      continue;   // the gimbal rule acts only above A_crit, with the gimbal finger in the grasp
    }
    out.push_back(h);
  }
  return out;
}

namespace {

// contact_signature(state) == s, without building one.
bool matches(const ContactSignature& s, const State& state) {
  if (s.finger_body.size() != state.fingers.size() || s.floor_points.size() != state.bodies.size() ||
      s.pair_points.size() != 3 * state.pairs.size())
    return false;
  for (std::size_t f = 0; f < state.fingers.size(); ++f) {
    const FingerState& fs = state.fingers[f];
    if (s.finger_body[f] != fs.body || s.finger_phase[f] != static_cast<int>(fs.phase)) return false;
  }
  for (std::size_t b = 0; b < state.bodies.size(); ++b) {
    const BodyState& bs = state.bodies[b];
    int active = 0;
    for (const VertexContact& vc : bs.floor_contacts) active += vc.active ? 1 : 0;
    if (s.floor_points[b] != active || s.asleep[b] != (bs.asleep ? 1 : 0)) return false;
  }
  for (std::size_t p = 0; p < state.pairs.size(); ++p) {
    const PairContact& pc = state.pairs[p];
    if (s.pair_points[3 * p] != pc.a || s.pair_points[3 * p + 1] != pc.b || s.pair_points[3 * p + 2] != pc.count)
      return false;
  }
  return true;
}

}  // namespace

StabilityMonitor::StabilityMonitor(const Model& model, ContactGather* contacts) : check_(model, contacts) {}

std::string StabilityMonitor::update(const State& state) {
  if (has_last_ && matches(last_, state)) return "";
  last_ = contact_signature(state);
  has_last_ = true;
  report_ = check_.analyse(state);
  ++analyses_;
  if (!report_.unstable()) return "";
  // A mode is its bodies and the springs that carry it (in any order): its motion's words and
  // its radius move with the pose.
  const StabilityMode& m = report_.groups[report_.worst];
  std::vector<std::string> springs = m.springs;
  std::sort(springs.begin(), springs.end());
  std::string key;
  for (int b : m.bodies) key += std::to_string(b) + ",";
  for (const std::string& s : springs) key += s + ";";
  if (std::find(warned_.begin(), warned_.end(), key) != warned_.end()) return "";
  warned_.push_back(key);
  return report_.warning(check_.model());
}

}  // namespace graspsim
