// The one gather of the bodies' contact points, each physics step: every floor point and every
// point between two bodies, with the penalty law at it (contact_law.hpp) and its friction anchor,
// as a Coupling. The paper's step clamps them, the implicit step solves them, the stability check
// turns them into springs, the energy accounting sums their springs.
//
// Which points: under the paper's step (h = 0) the points in contact now. Under the implicit step
// (h > 0) also those the step may reach, so that a contact arriving within a step is taken in by
// the step that would carry the bodies into it (an inelastic arrival), never found a step late as
// a spring already compressed, which would give back energy nobody put in:
//   floor      a point above the floor by less than h max(0, -u_n) + h^2 |g|
//   two bodies points apart by less than h (|v_a| + |v_b| + |w_a| r_a + |w_b| r_b) + 2 h^2 |g|
//              (r: the body's reach from its centre of mass). Absolute speeds, not the relative
//              one: two bodies falling together are apart at no speed until the lower one lands
//              and stops within the step; the upper one can then close up to its whole speed.
// Such a point enters the step with a negative depth; the step's active set (island_solve.hpp)
// keeps it only if the bodies would reach it.
//
// Cost: linear in bodies and contacts. Candidate pairs from FCL's dynamic AABB tree (the boxes
// grown by each body's reach over the step), sorted; the pairs with points kept in State::pairs,
// sorted, merged with the candidates in one pass.
#pragma once

#include <memory>
#include <vector>

#include "graspsim/engine/coupling.hpp"
#include "graspsim/engine/manifold.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

namespace detail {
struct FclWorld;   // the bodies' FCL objects (engine/src/fcl_world.hpp)
}

// Body b's floor points for a step of h s, appended to `out` as couplings (the law unclamped,
// world side a = -1, the friction anchors moved); `law` is floor_pair(model, b) and `radius` (m) at
// least the body's floor_reach (infinite: no vertex screened out by height before its full test).
// Returns how many are under the floor now. What the gather does for each body near the floor.
int floor_couplings(const Model& model, int b, const ContactPair& law, BodyState& bs, double h, double radius,
                    std::vector<Coupling>& out);

// Contact points a step holds before the lists that carry them grow: every floor point and finger,
// and kMaxPairPoints for each pair of bodies of a small scene, a dozen pairs a body beyond.
std::size_t pairs_room(std::size_t bodies);
std::size_t contact_room(const Model& model);

class ContactGather {
 public:
  // With `world`, the bodies' FCL objects are that world's, shared (Simulation shares one with
  // the fingers' CollisionWorld); without, its own.
  explicit ContactGather(const Model& model, std::shared_ptr<detail::FclWorld> world = nullptr);
  ~ContactGather();
  ContactGather(ContactGather&&) noexcept;
  ContactGather& operator=(ContactGather&&) noexcept;

  // Every contact point of the awake bodies at `state` for a step of h s (0: points in contact
  // only), appended to `out`: pairs in (a, b) order, each pair's points in the narrowphase's
  // order, then floor points body by body (after the pairs, which may wake a sleeper). `floor_points[b]` and `body_points[b]` (sized to the
  // bodies) get how many of each touch b (in contact now: depth > 0). Moves the friction anchors
  // (State: floor points, and `state.pairs`, rebuilt as the pairs with points), and, with sleep
  // on, wakes a sleeper that a moving body reaches or whose support went away. Two sleepers keep
  // their contact as it stands (counted, no coupling). Allocation-free once the contact set has
  // been as large as it is (the scratch keeps its capacity).
  void gather(const Model& model, State& state, double h, std::vector<Coupling>& out,
              std::vector<int>& floor_points, std::vector<int>& body_points);

  // Read only, for the stability check: the floor points active at the last step and the points
  // of the pairs in `state.pairs` at the pose now (anchors and their slipping flags as they
  // stand), appended to `out`, floor points body by body, then pairs.
  void last_contacts(const Model& model, const State& state, std::vector<Coupling>& out);

  // The energy the contact springs hold at `state` (J), per body (`per_body`, sized to the
  // bodies, added to; a pair's shared half and half), as the next step will take them: each point
  // in contact now, 1/2 k d^2 for its depth, and 1/2 k |s|^2 for its friction anchor's stretch s
  // (the anchors `state` keeps), limited to the friction circle the step's anchor rule would leave
  // it on (a point that slid during the step has given the rest to friction). Floor points and
  // every pair of bodies overlapping now. Leaves the state alone; places the broadphase at it.
  // Returns the total.
  double spring_energy(const Model& model, const State& state, std::vector<double>* per_body = nullptr);

  // Read only: the points of bodies a < b at `state` apart by less than `margin` (m), into `out`
  // (room for kMaxPairPoints). For tests and the energy accounting.
  int pair_points(const Model& model, const State& state, int a, int b, ManifoldPoint* out, double margin = 0.0);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspsim
