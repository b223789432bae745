// The bodies' mechanical energy, and a watch on the energy of bodies that nothing powers: a
// blow-up caught where it starts.
//
// E = sum over bodies of 1/2 m v^2 + 1/2 w . I w + m |g| z, plus the energy every contact spring
// holds (ContactGather::spring_energy: floor and body-body points, normal and friction springs).
//
// Contact is passive, so a group of touching bodies that no finger has touched since the last
// physics step cannot gain energy. The watch takes each such group's energy when the group forms,
// or when a finger last left it, as its reference E_ref, and reports the group once E - E_ref passes
// what the step's own law allows:
//   implicit  nothing but rounding and what the step's linearisation leaves out, accumulated since
//             the reference:
//               rounding     1e-9 (|E_ref| + 1 J)
//               turning      per step and body, F h^2 |w|^2 r: the step moves a contact point by
//                            h (v + w x r), a body turning moves it on a circle, (h |w|)^2 r / 2
//                            off that line, and its contact force F does that much more work on
//                            the spring (twice, for the linearised normal and turn together)
//               re-featuring per step and pair that was touching at the last step, the springs of
//                            its points with features new at this step (a face contact where an
//                            edge met a face): the gather finds the geometry anew, and a point of
//                            a new feature at once holds 1/2 k d^2. A pair that appears already
//                            overlapping is a contact the step missed, and is not allowed for
//   paper     1/4 K_ref + sum of m |g| r: the explicit step trades energy back and forth by O(h w)
//             of a mode's energy (a shadow energy is what it conserves), bounded at a stable rate;
//             a quarter of the motion's energy at the reference plus lifting each body by its own
//             reach r is past any such wobble, and an unstable step passes it within a few steps.
// Fingers, the gimbal's twist and the hands behind them are energy sources: a group a finger
// touches is not watched, and its reference is taken again when the finger leaves.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "graspsim/engine/contact_gather.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

// J: the bodies' mechanical energy at `state` (kinetic, gravity from z = 0, and every contact
// spring as `contacts` measures it), with each body's share in `per_body` (sized to the bodies,
// overwritten; a pair's springs half to each body) when given.
double mechanical_energy(const Model& model, const State& state, ContactGather& contacts,
                         std::vector<double>* per_body = nullptr);

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
  // With `contacts`, the contact springs are measured by that gather (a Simulation's: one FCL
  // world a run); without, by one of its own.
  explicit EnergyWatch(const Model& model, ContactGather* contacts = nullptr);
  void use_contacts(ContactGather& contacts) {
    contacts_ = &contacts;
    own_.reset();
  }

  // After a physics step at `time` s: the first unpowered group (lowest body index) whose energy
  // has grown past its bound, once per reference; nullopt when none has.
  std::optional<EnergyGain> after_physics(const State& state, double time);

 private:
  void group(const State& state);
  void allowance(const State& state);

  const Model& model_;
  std::unique_ptr<ContactGather> own_;   // when no gather was given
  ContactGather* contacts_;
  std::vector<double> reach_;          // m, per body: farthest floor point from the centre
  std::vector<int> parent_;            // union-find over touching bodies, this step
  std::vector<int> root_before_;       // per body: its group's lowest index at the last step (-1: powered)
  std::vector<int> size_before_;       // per body: its group's size at the last step
  std::vector<double> reference_;      // J, per group root: E_ref
  std::vector<double> kinetic_ref_;    // J, per group root: K_ref
  std::vector<double> allowed_;        // J, per group root: the implicit step's allowance since E_ref
  std::vector<double> since_;          // s, per group root
  std::vector<std::uint8_t> reported_; // per group root: reported for this reference
  std::vector<std::uint8_t> touched_;         // per body: a finger touches it now
  std::vector<std::uint8_t> touched_before_;  // per body: one did at the last step
  std::vector<std::uint8_t> group_powered_;   // per group root: a finger touches a member
  std::vector<std::uint8_t> group_same_;      // per group root: the same members as at the last step
  std::vector<double> energy_, kinetic_, group_allowance_;   // J, per group root, this step
  std::vector<double> step_allowance_, springs_, body_energy_;   // J, per body, this step
  std::vector<int> size_;              // per group root
  std::vector<Vec3> velocity_before_;  // m/s, per body: at the last physics step
  std::vector<PairContact> pairs_before_;   // the pairs touching at the last step (their keys)
  bool has_before_ = false;
  int find(int b);
};

}  // namespace graspsim
