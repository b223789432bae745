// The bodies' mechanical energy and the energy watch (energy.hpp).
#include "graspsim/engine/energy.hpp"

#include <algorithm>
#include <cmath>

#include "graspsim/engine/floor_points.hpp"

namespace graspsim {

namespace {

// J: body b's kinetic energy and its energy in gravity from z = 0.
double motion_energy(const Model& model, const State& state, int b, double* kinetic = nullptr) {
  const BodyParams& bp = model.bodies[b];
  const BodyState& bs = state.bodies[b];
  const Vec3 w_b = bs.rotation.transpose() * bs.angular_velocity;   // rad/s, body frame
  const double k = 0.5 * bp.mass * bs.velocity.squaredNorm() + 0.5 * w_b.dot(bp.inertia.cwiseProduct(w_b));
  if (kinetic != nullptr) *kinetic = k;
  return k - bp.mass * model.gravity.dot(bs.position);
}

}  // namespace

double mechanical_energy(const Model& model, const State& state, ContactGather& contacts, std::vector<double>* per_body) {
  double total = 0.0;
  if (per_body != nullptr) per_body->assign(model.bodies.size(), 0.0);
  for (std::size_t b = 0; b < model.bodies.size(); ++b) {
    const double e = motion_energy(model, state, static_cast<int>(b));
    total += e;
    if (per_body != nullptr) (*per_body)[b] += e;
  }
  return total + contacts.spring_energy(model, state, per_body);
}

EnergyWatch::EnergyWatch(const Model& model, ContactGather* contacts)
    : model_(model), own_(contacts ? nullptr : std::make_unique<ContactGather>(model)),
      contacts_(contacts ? contacts : own_.get()) {
  const std::size_t n = model.bodies.size();
  for (std::size_t b = 0; b < n; ++b) reach_.push_back(floor_reach(model.bodies[b].shape));
  parent_.resize(n);
  root_before_.assign(n, -1);
  size_before_.assign(n, 0);
  reference_.assign(n, 0.0);
  kinetic_ref_.assign(n, 0.0);
  allowed_.assign(n, 0.0);
  since_.assign(n, 0.0);
  reported_.assign(n, 0);
  touched_.assign(n, 0);
  touched_before_.assign(n, 0);
  group_powered_.assign(n, 0);
  group_same_.assign(n, 1);
  energy_.assign(n, 0.0);
  kinetic_.assign(n, 0.0);
  step_allowance_.assign(n, 0.0);
  group_allowance_.assign(n, 0.0);
  springs_.assign(n, 0.0);
  size_.assign(n, 0);
  velocity_before_.assign(n, Vec3::Zero());
}

int EnergyWatch::find(int b) {
  while (parent_[b] != b) b = parent_[b] = parent_[parent_[b]];
  return b;
}

// Groups: bodies joined by body-body contact points at this step.
void EnergyWatch::group(const State& state) {
  for (std::size_t b = 0; b < parent_.size(); ++b) parent_[b] = static_cast<int>(b);
  for (const PairContact& pc : state.pairs) {
    const int ra = find(pc.a), rb = find(pc.b);
    if (ra != rb) parent_[std::max(ra, rb)] = std::min(ra, rb);
  }
}

// The implicit step's allowance of this step, per body (energy.hpp): the turning term, and half
// of each re-featured pair's new springs to each of its bodies.
void EnergyWatch::allowance(const State& state) {
  const int n = static_cast<int>(model_.bodies.size());
  std::fill(step_allowance_.begin(), step_allowance_.end(), 0.0);
  if (model_.integrator != Integrator::kImplicit || !has_before_) return;
  const double h = 1.0 / model_.rates.physics;
  // Contact force on each body: its net change of momentum less gravity, and its springs' force
  // sqrt(2 k U) (a spring of energy U pushes with that; a body squeezed between two contacts has
  // no net force but both springs).
  std::vector<double>& springs = springs_;
  springs.assign(n, 0.0);
  contacts_->spring_energy(model_, state, &springs);
  for (int b = 0; b < n; ++b) {
    const BodyState& bs = state.bodies[b];
    if (bs.asleep) continue;
    double k = model_.floor.enabled ? floor_pair(model_, b).stiffness : 0.0;
    for (const PairContact& pc : state.pairs) {
      if (pc.a == b || pc.b == b) k = std::max(k, body_pair(model_, pc.a, pc.b).stiffness);
    }
    const double net = model_.bodies[b].mass * ((bs.velocity - velocity_before_[b]) / h - model_.gravity).norm();
    const double force = net + (std::isfinite(k) ? std::sqrt(2.0 * k * springs[b]) : 0.0);   // N
    const double turn = h * bs.angular_velocity.norm();                                       // rad
    step_allowance_[b] += force * turn * turn * reach_[b];
  }
  // Re-featuring: a pair touching at the last step too, its points of features new at this step.
  ManifoldPoint points[kMaxPairPoints];
  std::size_t before = 0;
  for (const PairContact& pc : state.pairs) {
    while (before < pairs_before_.size() &&
           std::make_pair(pairs_before_[before].a, pairs_before_[before].b) < std::make_pair(pc.a, pc.b))
      ++before;
    if (before == pairs_before_.size() || pairs_before_[before].a != pc.a || pairs_before_[before].b != pc.b) continue;
    const PairContact& last = pairs_before_[before];
    const double k = body_pair(model_, pc.a, pc.b).stiffness;
    const int found = contacts_->pair_points(model_, state, pc.a, pc.b, points);
    for (int i = 0; i < found; ++i) {
      bool known = false;
      for (int j = 0; j < last.count && !known; ++j) known = last.points[j].key == points[i].key;
      if (known) continue;
      const double e = 0.5 * k * points[i].depth * points[i].depth;
      step_allowance_[pc.a] += 0.5 * e;
      step_allowance_[pc.b] += 0.5 * e;
    }
  }
}

std::optional<EnergyGain> EnergyWatch::after_physics(const State& state, double time) {
  const int n = static_cast<int>(model_.bodies.size());
  group(state);
  allowance(state);
  // Powered: a finger touches the body now, or touched it at the last step (its push in the
  // window just ended still reached this step).
  std::fill(touched_.begin(), touched_.end(), 0);
  for (const FingerState& fs : state.fingers) {
    if (fs.body >= 0) touched_[fs.body] = 1;
  }
  mechanical_energy(model_, state, *contacts_, &body_energy_);
  std::vector<double>& group_allowance = group_allowance_;
  std::vector<double>& kinetic = kinetic_;
  std::vector<double>& energy = energy_;
  std::fill(group_allowance.begin(), group_allowance.end(), 0.0);
  std::fill(kinetic.begin(), kinetic.end(), 0.0);
  std::fill(energy.begin(), energy.end(), 0.0);
  std::fill(size_.begin(), size_.end(), 0);
  std::fill(group_powered_.begin(), group_powered_.end(), 0);
  std::fill(group_same_.begin(), group_same_.end(), 1);
  for (int b = 0; b < n; ++b) {
    const int r = find(b);
    double k = 0.0;
    motion_energy(model_, state, b, &k);
    kinetic[r] += k;
    energy[r] += body_energy_[b];
    group_allowance[r] += step_allowance_[b];
    ++size_[r];
    if (touched_[b] || touched_before_[b]) group_powered_[r] = 1;
    if (root_before_[b] != r) group_same_[r] = 0;
  }
  std::optional<EnergyGain> found;
  for (int r = 0; r < n; ++r) {
    if (find(r) != r) continue;
    if (size_[r] != size_before_[r]) group_same_[r] = 0;
    if (group_powered_[r] || !group_same_[r]) {
      // A new group, or one a finger powered: its energy now is its reference.
      reference_[r] = energy[r];
      kinetic_ref_[r] = kinetic[r];
      allowed_[r] = 0.0;
      since_[r] = time;
      reported_[r] = 0;
      continue;
    }
    allowed_[r] += group_allowance[r];
    double bound = 0.0;
    if (model_.integrator == Integrator::kImplicit) {
      bound = 1e-9 * (std::abs(reference_[r]) + 1.0) + allowed_[r];
    } else {
      bound = 0.25 * kinetic_ref_[r];
      for (int b = r; b < n; ++b) {
        if (find(b) == r) bound += model_.bodies[b].mass * model_.gravity.norm() * reach_[b];
      }
      bound = std::max(bound, 1e-9);
    }
    if (!reported_[r] && energy[r] - reference_[r] > bound && !found) {
      reported_[r] = 1;
      found = EnergyGain{r, size_[r], energy[r], reference_[r], bound, since_[r]};
    }
  }
  for (int b = 0; b < n; ++b) {
    const int r = find(b);
    root_before_[b] = group_powered_[r] ? -1 : r;
    size_before_[b] = size_[r];
    touched_before_[b] = touched_[b];
    velocity_before_[b] = state.bodies[b].velocity;
  }
  pairs_before_.assign(state.pairs.begin(), state.pairs.end());
  has_before_ = true;
  return found;
}

}  // namespace graspsim
