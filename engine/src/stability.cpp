// The stability check's inputs (stability.hpp): the couplings and grasp hinges of a state, the
// contact signature, and the monitor that re-runs the analysis (stability_modes.cpp) when the
// signature changes.
#include "graspsim/engine/stability.hpp"

#include <algorithm>
#include <cmath>

#include "graspsim/engine/finger_contact.hpp"
#include "graspsim/engine/grasp_rules.hpp"

namespace graspsim {
namespace {

// A contact's spring (or damper) of coefficient k: isotropic while it holds, along the normal
// only while it slips (the tangential force then sits on the friction cone, mu f_n, and no
// longer follows the displacement).
Mat3 law(double k, const Vec3& n, bool slipping) {
  return slipping ? Mat3(k * n * n.transpose()) : Mat3(k * Mat3::Identity());
}

bool finite_law(const ContactPair& p) { return std::isfinite(p.stiffness) && std::isfinite(p.damping); }

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
  for (const PairContact& pc : state.pairs) s.pair_points.push_back(pc.count);
  return s;
}

StabilityCheck::StabilityCheck(const Model& model) : model_(model), contacts_(model_) {}

std::string StabilityCheck::name(const StabilityCoupling& c) const {
  switch (c.kind) {
    case StabilityCoupling::Kind::kFinger: return "finger " + quoted(model_.fingers[c.finger].name);
    case StabilityCoupling::Kind::kFloor: return "the floor under " + quoted(model_.bodies[c.b].name);
    case StabilityCoupling::Kind::kBody:
      return "the contact of " + quoted(model_.bodies[c.a].name) + " and " + quoted(model_.bodies[c.b].name);
  }
  return "?";
}

std::vector<StabilityCoupling> StabilityCheck::couplings(const State& state) {
  std::vector<StabilityCoupling> out;
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
    const Vec3 n = bs.rotation * fs.normal;
    const bool slipping = fs.phase == ContactPhase::kSlip;
    StabilityCoupling c;
    c.kind = StabilityCoupling::Kind::kFinger;
    c.b = fs.body;
    c.finger = static_cast<int>(f);
    c.point = bs.rotation * fs.god_object + bs.position - model_.fingers[f].radius * n;
    c.stiffness = law(pair.stiffness, n, slipping);
    c.damping = law(model_.fingers[f].damping, n, slipping);
    out.push_back(c);
  }
  // Floor points that touched at the last step, at the pose now. A contact law left infinite
  // (only possible when the integrator chooses it) has no spring to analyse here.
  if (model_.floor.enabled) {
    for (std::size_t b = 0; b < state.bodies.size(); ++b) {
      const BodyState& bs = state.bodies[b];
      const BodyParams& bp = model_.bodies[b];
      const ContactPair pair = contact_pair(bp.material, model_.floor.material);
      if (!finite_law(pair)) continue;
      for (std::size_t k = 0; k < bs.floor_contacts.size(); ++k) {
        const VertexContact& vc = bs.floor_contacts[k];
        if (!vc.active) continue;
        bool rolling = false;
        StabilityCoupling c;
        c.kind = StabilityCoupling::Kind::kFloor;
        c.b = static_cast<int>(b);
        c.point = bs.position + floor_point(bp.shape, bs.rotation, static_cast<int>(k), rolling);
        c.stiffness = law(pair.stiffness, Vec3::UnitZ(), vc.slipping);
        c.damping = law(pair.damping, Vec3::UnitZ(), vc.slipping);
        out.push_back(c);
      }
    }
  }
  // Body pairs that touched at the last step: their manifold at the pose now, each point's
  // slipping flag from the anchor with its key.
  const int nb = static_cast<int>(state.bodies.size());
  ManifoldPoint points[kMaxPairPoints];
  for (int a = 0; a < nb; ++a) {
    for (int b = a + 1; b < nb; ++b) {
      const PairContact& pc = state.pairs[pair_index(a, b, nb)];
      if (pc.count == 0) continue;
      const ContactPair pair = contact_pair(model_.bodies[a].material, model_.bodies[b].material);
      if (!finite_law(pair)) continue;
      const int n = contacts_.points(model_, state, a, b, points);
      for (int i = 0; i < n; ++i) {
        bool slipping = false;
        for (int j = 0; j < pc.count; ++j) {
          if (pc.points[j].key == points[i].key) slipping = pc.points[j].slipping;
        }
        StabilityCoupling c;
        c.kind = StabilityCoupling::Kind::kBody;
        c.a = a;
        c.b = b;
        c.point = points[i].point;
        c.stiffness = law(pair.stiffness, points[i].normal, slipping);
        c.damping = law(pair.damping, points[i].normal, slipping);
        out.push_back(c);
      }
    }
  }
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
      s.pair_points.size() != state.pairs.size())
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
    if (s.pair_points[p] != state.pairs[p].count) return false;
  }
  return true;
}

}  // namespace

StabilityMonitor::StabilityMonitor(const Model& model) : check_(model) {}

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
