// A watch on the energy of bodies that nothing powers: a blow-up caught where it starts.
//
// Contact with the floor and between bodies is passive: it can store energy in its springs and
// give it back, or lose it, but never make it. A group of bodies that touch one another (and
// maybe the floor) with no finger on any of them since the last physics step therefore has a
// mechanical energy
//   E = sum over its bodies of 1/2 m v^2 + 1/2 w . I w + m |g| z + 1/2 k_n d^2 per floor point
// (d the point's depth, k_n the floor's normal stiffness) that cannot grow. The paper's explicit
// step, run where its coupled modes are unstable (stability.hpp), grows it by a factor at every
// step. The watch takes each such group's energy when the group forms, or when a finger last left
// it, as its reference E_ref, and reports the group once
//   E - E_ref > 1/4 K_ref + sum of m |g| r
// (K_ref the group's kinetic energy at the reference, r each body's reach from its centre of mass
// to its farthest floor point): more than a quarter of its motion's energy, plus the energy of
// lifting each body by its own size. Stable runs stay far inside (a rocking body trades its
// energy back and forth; an explicit step at a stable rate keeps a bounded error), and a growth by
// a factor per step passes it within a few steps. Fingers, the gimbal's twist and the hands behind
// them are energy sources: a group a finger touches is not watched, and its reference is taken
// again when the finger leaves.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

struct EnergyGain {
  int body = -1;            // the group's lowest body index
  int bodies = 0;           // 1: bodies in the group
  double energy = 0.0;      // J: the group's energy now
  double reference = 0.0;   // J: its energy when the watch took it
  double bound = 0.0;       // J: the growth allowed over the reference
  double since = 0.0;       // s: when the reference was taken
};

class EnergyWatch {
 public:
  explicit EnergyWatch(const Model& model);

  // After a physics step at `time` s: the first unpowered group (lowest body index) whose energy
  // has grown past its bound, once per reference; nullopt when none has.
  std::optional<EnergyGain> after_physics(const State& state, double time);

  // J: body b's mechanical energy in `state` (kinetic, gravity from z = 0, floor springs).
  double body_energy(const State& state, int b) const;

 private:
  const Model& model_;
  std::vector<double> reach_;          // m, per body: farthest floor point from the centre
  std::vector<double> floor_k_;        // N/m, per body: the floor's normal stiffness per point
  std::vector<int> parent_;            // union-find over touching bodies, this step
  std::vector<int> root_before_;       // per body: its group's lowest index at the last step (-1: powered)
  std::vector<int> size_before_;       // per body: its group's size at the last step
  std::vector<double> reference_;      // J, per group root: E_ref
  std::vector<double> kinetic_ref_;    // J, per group root: K_ref
  std::vector<double> since_;          // s, per group root
  std::vector<std::uint8_t> reported_; // per group root: reported for this reference
  std::vector<std::uint8_t> touched_;         // per body: a finger touches it now
  std::vector<std::uint8_t> touched_before_;  // per body: one did at the last step
  std::vector<std::uint8_t> group_powered_;   // per group root: a finger touches a member
  std::vector<std::uint8_t> group_same_;      // per group root: the same members as at the last step
  std::vector<double> energy_, kinetic_;   // J, per group root, this step
  std::vector<int> size_;              // per group root
  int find(int b);
};

}  // namespace graspsim
