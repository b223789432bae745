// The energy watch (energy.hpp).
#include "graspsim/engine/energy.hpp"

#include <algorithm>
#include <cmath>

#include "graspsim/engine/object_contact.hpp"

namespace graspsim {

EnergyWatch::EnergyWatch(const Model& model) : model_(model) {
  const std::size_t n = model.bodies.size();
  for (std::size_t b = 0; b < n; ++b) {
    reach_.push_back(floor_reach(model.bodies[b].shape));
    const double k = model.floor.enabled ? floor_pair(model, static_cast<int>(b)).stiffness : 0.0;
    floor_k_.push_back(std::isfinite(k) ? k : 0.0);
  }
  parent_.resize(n);
  root_before_.assign(n, -1);
  size_before_.assign(n, 0);
  reference_.assign(n, 0.0);
  kinetic_ref_.assign(n, 0.0);
  since_.assign(n, 0.0);
  reported_.assign(n, 0);
  touched_.assign(n, 0);
  touched_before_.assign(n, 0);
  group_powered_.assign(n, 0);
  group_same_.assign(n, 1);
  energy_.assign(n, 0.0);
  kinetic_.assign(n, 0.0);
  size_.assign(n, 0);
}

int EnergyWatch::find(int b) {
  while (parent_[b] != b) b = parent_[b] = parent_[parent_[b]];
  return b;
}

double EnergyWatch::body_energy(const State& state, int b) const {
  const BodyParams& bp = model_.bodies[b];
  const BodyState& bs = state.bodies[b];
  const Vec3 w_b = bs.rotation.transpose() * bs.angular_velocity;   // rad/s, body frame
  double e = 0.5 * bp.mass * bs.velocity.squaredNorm() + 0.5 * w_b.dot(bp.inertia.cwiseProduct(w_b)) -
             bp.mass * model_.gravity.dot(bs.position);
  if (floor_k_[b] > 0.0) {
    for (int k = 0; k < floor_point_count(bp.shape); ++k) {
      bool rolling = false;
      const double depth = model_.floor.height - (bs.position + floor_point(bp.shape, bs.rotation, k, rolling)).z();
      if (depth > 0.0) e += 0.5 * floor_k_[b] * depth * depth;
    }
  }
  return e;
}

std::optional<EnergyGain> EnergyWatch::after_physics(const State& state, double time) {
  const int n = static_cast<int>(model_.bodies.size());
  // Groups: bodies joined by body-body contact points at this step.
  for (int b = 0; b < n; ++b) parent_[b] = b;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      if (state.pairs[pair_index(a, b, n)].count == 0) continue;
      const int ra = find(a), rb = find(b);
      if (ra != rb) parent_[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  // Powered: a finger touches the body now, or touched it at the last step (its push in the
  // window just ended still reached this step).
  std::fill(touched_.begin(), touched_.end(), 0);
  for (const FingerState& fs : state.fingers) {
    if (fs.body >= 0) touched_[fs.body] = 1;
  }
  std::fill(energy_.begin(), energy_.end(), 0.0);
  std::fill(kinetic_.begin(), kinetic_.end(), 0.0);
  std::fill(size_.begin(), size_.end(), 0);
  std::fill(group_powered_.begin(), group_powered_.end(), 0);
  std::fill(group_same_.begin(), group_same_.end(), 1);
  for (int b = 0; b < n; ++b) {
    const int r = find(b);
    const BodyParams& bp = model_.bodies[b];
    const BodyState& bs = state.bodies[b];
    const Vec3 w_b = bs.rotation.transpose() * bs.angular_velocity;
    kinetic_[r] += 0.5 * bp.mass * bs.velocity.squaredNorm() + 0.5 * w_b.dot(bp.inertia.cwiseProduct(w_b));
    energy_[r] += body_energy(state, b);
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
      reference_[r] = energy_[r];
      kinetic_ref_[r] = kinetic_[r];
      since_[r] = time;
      reported_[r] = 0;
      continue;
    }
    double bound = 0.25 * kinetic_ref_[r];
    for (int b = r; b < n; ++b) {
      if (find(b) == r) bound += model_.bodies[b].mass * model_.gravity.norm() * reach_[b];
    }
    bound = std::max(bound, 1e-9);
    if (!reported_[r] && energy_[r] - reference_[r] > bound && !found) {
      reported_[r] = 1;
      found = EnergyGain{r, size_[r], energy_[r], reference_[r], bound, since_[r]};
    }
  }
  for (int b = 0; b < n; ++b) {
    const int r = find(b);
    root_before_[b] = group_powered_[r] ? -1 : r;
    size_before_[b] = size_[r];
    touched_before_[b] = touched_[b];
  }
  return found;
}

}  // namespace graspsim
